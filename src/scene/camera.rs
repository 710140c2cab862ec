//! The camera: a pinhole (or thin lens) perspective projection.

use crate::error::{Error, Result, check_finite, check_finite3};
use glam::Vec3A;

/// A perspective camera looking from `eye` towards `target`. Image right is
/// `normalize(cross(target - eye, up))`, image up is perpendicular to it and the view direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
    /// Thin-lens aperture radius; 0 is a pinhole.
    pub lens_radius: f32,
    /// Distance of the plane in focus; 0 means the distance from eye to target.
    pub focus_distance: f32,
}

impl Default for Camera {
    /// The Cornell box's camera.
    fn default() -> Self {
        Camera {
            eye: [278.0, 273.0, -800.0],
            target: [278.0, 273.0, -799.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 39.307_648,
            lens_radius: 0.0,
            focus_distance: 0.0,
        }
    }
}

/// A validated camera with its frame, ready to generate rays for a given image size.
#[derive(Clone, Copy, Debug)]
pub struct CameraModel {
    pub eye: Vec3A,
    pub forward: Vec3A,
    pub right: Vec3A,
    pub up: Vec3A,
    /// Half extent of the image plane at distance 1: (tan(fov/2)·aspect, tan(fov/2)).
    pub half_width: f32,
    pub half_height: f32,
    pub lens_radius: f32,
    pub focus_distance: f32,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    pub fn validate(&self) -> Result<()> {
        check_finite3("camera.eye", self.eye)?;
        check_finite3("camera.target", self.target)?;
        check_finite3("camera.up", self.up)?;
        check_finite(&"camera.fov_y_deg", self.fov_y_deg)?;
        check_finite(&"camera.lens_radius", self.lens_radius)?;
        check_finite(&"camera.focus_distance", self.focus_distance)?;
        let eye = Vec3A::from(self.eye);
        let view = Vec3A::from(self.target) - eye;
        if !view.is_finite() {
            return Err(Error::invalid(format!(
                "camera.target {:?} - camera.eye {:?} overflows a float; the view direction is undefined",
                self.target, self.eye
            )));
        }
        let scale = eye.abs().max_element().max(1.0);
        if view.length() <= 1e-6 * scale {
            return Err(Error::invalid(format!(
                "camera.eye {:?} and camera.target {:?} coincide; the view direction is undefined",
                self.eye, self.target
            )));
        }
        let up = Vec3A::from(self.up);
        if up == Vec3A::ZERO {
            return Err(Error::invalid("camera.up is the zero vector"));
        }
        // The camera frame is built in single precision: an up whose squared length
        // underflows or overflows has no direction there.
        let length_squared = up.length_squared();
        if !(length_squared.is_finite() && length_squared >= f32::MIN_POSITIVE) {
            return Err(Error::invalid(format!(
                "camera.up {:?} is too short or too long to normalize in single precision; scale it towards unit length",
                self.up
            )));
        }
        let sin_angle = view.normalize().cross(up.normalize()).length();
        if sin_angle < 1e-4 {
            return Err(Error::invalid(format!(
                "camera.up {:?} is parallel to the view direction {:?}; the image orientation is undefined",
                self.up,
                view.normalize().to_array()
            )));
        }
        // `model` crosses the unnormalized up with the view direction.
        if !view.normalize().cross(up).normalize().is_finite() {
            return Err(Error::invalid(format!(
                "camera.up {:?} is too short for single precision at its angle to the view direction; scale it towards unit length",
                self.up
            )));
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(Error::invalid(format!(
                "camera.fov_y_deg is {}; the vertical field of view must be in (0, 180) degrees",
                self.fov_y_deg
            )));
        }
        if self.lens_radius < 0.0 {
            return Err(Error::invalid(format!(
                "camera.lens_radius is {}; it must be 0 (pinhole) or positive",
                self.lens_radius
            )));
        }
        if self.focus_distance < 0.0 {
            return Err(Error::invalid(format!(
                "camera.focus_distance is {}; it must be 0 (focus on the target) or positive",
                self.focus_distance
            )));
        }
        Ok(())
    }

    /// The frame for an image of `width` × `height` pixels. Call `validate` first. Hidden:
    /// `CameraModel` is internal.
    #[doc(hidden)]
    pub fn model(&self, width: u32, height: u32) -> CameraModel {
        let eye = Vec3A::from(self.eye);
        let view = Vec3A::from(self.target) - eye;
        let forward = view.normalize();
        let right = forward.cross(Vec3A::from(self.up)).normalize();
        let up = right.cross(forward);
        let half_height = (self.fov_y_deg.to_radians() * 0.5).tan();
        let half_width = half_height * width as f32 / height as f32;
        CameraModel {
            eye,
            forward,
            right,
            up,
            half_width,
            half_height,
            lens_radius: self.lens_radius,
            focus_distance: if self.focus_distance > 0.0 {
                self.focus_distance
            } else {
                view.length()
            },
            width,
            height,
        }
    }
}

impl CameraModel {
    /// Checks that every primary ray is finite and unit length: the image corners with the
    /// lens's extreme points bound all of them. Catches lens radii and focus distances that
    /// overflow the float range together with the field of view and position.
    pub fn validate(&self) -> Result<()> {
        let (w, h) = (self.width as f32, self.height as f32);
        let lens_points = [
            [0.5, 0.5],
            [0.0, 0.5],
            [1.0, 0.5],
            [0.5, 0.0],
            [0.5, 1.0],
            [0.0, 0.0],
            [1.0, 1.0],
        ];
        for (x, y) in [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)] {
            for lens in lens_points {
                let (origin, direction) = self.generate_ray(x, y, lens);
                if !(origin.is_finite()
                    && direction.is_finite()
                    && (direction.length() - 1.0).abs() < 1e-3)
                {
                    return Err(Error::invalid(format!(
                        "camera.lens_radius {} and camera.focus_distance {} with a vertical field of view of {} degrees from camera.eye {:?} give primary rays outside the float range",
                        self.lens_radius,
                        self.focus_distance,
                        2.0 * self.half_height.atan().to_degrees(),
                        self.eye.to_array()
                    )));
                }
            }
        }
        Ok(())
    }

    /// The angle a pixel spans seen from the lens (at the image's centre; its height on the
    /// image plane at distance 1): the spread of the ray cone through a pixel. Rays from one
    /// lens point through a pixel's area on the focal plane form that cone, thin lens or not.
    #[inline]
    pub fn pixel_spread_angle(&self) -> f32 {
        2.0 * self.half_height / self.height as f32
    }

    /// The primary ray through film position (x, y) in pixels, (0, 0) the top-left corner.
    /// `lens` is a point in the unit square used only by a thin lens. Returns (origin, unit direction).
    #[inline]
    pub fn generate_ray(&self, x: f32, y: f32, lens: [f32; 2]) -> (Vec3A, Vec3A) {
        let sx = (2.0 * x / self.width as f32 - 1.0) * self.half_width;
        let sy = (1.0 - 2.0 * y / self.height as f32) * self.half_height;
        let dir = self.forward + self.right * sx + self.up * sy;
        if self.lens_radius > 0.0 {
            let [lx, ly] = crate::sampling::uniform_disk(lens);
            let offset = (self.right * lx + self.up * ly) * self.lens_radius;
            // The point in focus lies where the pinhole ray crosses the focal plane.
            let focus = self.eye + dir * self.focus_distance;
            let origin = self.eye + offset;
            (origin, (focus - origin).normalize())
        } else {
            (self.eye, dir.normalize())
        }
    }
}

/// The camera as an endpoint of light paths: where a direction lands on the film and the
/// importance and densities bidirectional methods need. Importance is normalized so that
/// a pixel's measurement equals its mean radiance (the quantity the path tracer estimates).
#[derive(Clone, Copy, Debug)]
pub struct CameraImportance {
    /// Importance We of the ray.
    pub importance: f32,
    /// Continuous film position in pixels, (0, 0) the top-left corner.
    pub raster: [f32; 2],
}

impl CameraModel {
    /// Area of the image plane at distance 1 in front of the eye.
    #[inline]
    fn film_area(&self) -> f32 {
        4.0 * self.half_width * self.half_height
    }

    /// Area of the lens, or 1 for a pinhole (whose position density is a Dirac delta).
    #[inline]
    pub fn lens_area(&self) -> f32 {
        if self.lens_radius > 0.0 {
            std::f32::consts::PI * self.lens_radius * self.lens_radius
        } else {
            1.0
        }
    }

    /// Film position of the ray leaving lens point `origin` in unit direction `direction`,
    /// if it lands on the film.
    #[inline]
    pub fn raster_position(&self, origin: Vec3A, direction: Vec3A) -> Option<[f32; 2]> {
        let cos_theta = direction.dot(self.forward);
        if cos_theta <= 0.0 {
            return None;
        }
        // Through a thin lens, the ray meets the pinhole ray of the same film point on the
        // focal plane; a pinhole's origin is the eye and any plane will do.
        let focus = origin + direction * (self.focus_distance / cos_theta);
        let local = focus - self.eye;
        let depth = local.dot(self.forward);
        if depth <= 0.0 {
            return None;
        }
        let sx = local.dot(self.right) / depth;
        let sy = local.dot(self.up) / depth;
        let x = (sx / self.half_width + 1.0) * 0.5 * self.width as f32;
        let y = (1.0 - sy / self.half_height) * 0.5 * self.height as f32;
        if (0.0..self.width as f32).contains(&x) && (0.0..self.height as f32).contains(&y) {
            Some([x, y])
        } else {
            None
        }
    }

    /// Importance of the ray and where it lands, or None if it misses the film.
    #[inline]
    pub fn importance(&self, origin: Vec3A, direction: Vec3A) -> Option<CameraImportance> {
        let raster = self.raster_position(origin, direction)?;
        let cos_theta = direction.dot(self.forward);
        let cos2 = cos_theta * cos_theta;
        Some(CameraImportance {
            importance: 1.0 / (self.film_area() * self.lens_area() * cos2 * cos2),
            raster,
        })
    }

    /// Solid-angle density with which `generate_ray` produces `direction` (0 off the film).
    #[inline]
    pub fn direction_pdf(&self, origin: Vec3A, direction: Vec3A) -> f32 {
        if self.raster_position(origin, direction).is_none() {
            return 0.0;
        }
        let cos_theta = direction.dot(self.forward);
        1.0 / (self.film_area() * cos_theta * cos_theta * cos_theta)
    }

    /// The unit direction from lens point `lens` through film position (x, y) in pixels:
    /// towards where that film point's pinhole ray meets the focal plane (any direction from
    /// a pinhole's eye). Its solid-angle density, for (x, y) uniform on the film, is
    /// `direction_pdf` for any lens point.
    #[inline]
    pub fn direction_through(&self, lens: Vec3A, x: f32, y: f32) -> Vec3A {
        let sx = (2.0 * x / self.width as f32 - 1.0) * self.half_width;
        let sy = (1.0 - 2.0 * y / self.height as f32) * self.half_height;
        let dir = self.forward + self.right * sx + self.up * sy;
        if self.lens_radius > 0.0 {
            (self.eye + dir * self.focus_distance - lens).normalize()
        } else {
            dir.normalize()
        }
    }

    /// A lens point for connecting to `point`, from `u` in the unit square: the eye for a
    /// pinhole.
    #[inline]
    pub fn sample_lens(&self, u: [f32; 2]) -> Vec3A {
        if self.lens_radius > 0.0 {
            let [lx, ly] = crate::sampling::uniform_disk(u);
            self.eye + (self.right * lx + self.up * ly) * self.lens_radius
        } else {
            self.eye
        }
    }
}
