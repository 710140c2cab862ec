//! A render's request checked once, where it enters (`render`, `jobs::plan`, a plan read
//! from bytes, a job's own thread count, the C ABI): settings that passed
//! `RenderSettings::validate` (`ValidSettings`), and with them a valid camera and its model
//! for the image (`RenderRequest`). Only the constructors here make them, so the layers
//! below, which take them, are reached with checked values alone and check nothing again.

use super::RenderSettings;
use crate::error::Result;
use crate::scene::{Camera, CameraModel};
use std::ops::Deref;

/// Settings that passed `RenderSettings::validate`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ValidSettings(RenderSettings);

impl ValidSettings {
    pub(crate) fn new(settings: &RenderSettings) -> Result<Self> {
        settings.validate()?;
        Ok(ValidSettings(*settings))
    }

    /// The request of a render of these settings seen by `camera`, once it and its model
    /// for the image are checked.
    pub(crate) fn with_camera(self, camera: &Camera) -> Result<RenderRequest> {
        camera.validate()?;
        let model = camera.model(self.width, self.height);
        model.validate()?;
        Ok(RenderRequest {
            settings: self,
            camera: *camera,
            model,
        })
    }
}

impl Deref for ValidSettings {
    type Target = RenderSettings;

    fn deref(&self) -> &RenderSettings {
        &self.0
    }
}

/// A render's valid settings, its valid camera and the camera's model for the image.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RenderRequest {
    settings: ValidSettings,
    camera: Camera,
    /// Follows from the two above.
    model: CameraModel,
}

impl RenderRequest {
    pub(crate) fn settings(&self) -> &ValidSettings {
        &self.settings
    }

    pub(crate) fn camera(&self) -> &Camera {
        &self.camera
    }

    pub(crate) fn model(&self) -> &CameraModel {
        &self.model
    }

    /// The same render on `threads` threads (a job's own count): the settings enter anew.
    pub(crate) fn with_threads(&self, threads: u32) -> Result<RenderRequest> {
        let settings = ValidSettings::new(&RenderSettings {
            threads,
            ..*self.settings
        })?;
        Ok(RenderRequest { settings, ..*self })
    }
}

/// The model follows from the settings and the camera.
impl PartialEq for RenderRequest {
    fn eq(&self, other: &Self) -> bool {
        self.settings == other.settings && self.camera == other.camera
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::MLT_MAX_THREADS;

    #[test]
    fn only_checked_values_make_a_request() {
        let settings = RenderSettings::default();
        let camera = Camera::default();
        let request = ValidSettings::new(&settings)
            .unwrap()
            .with_camera(&camera)
            .unwrap();
        assert_eq!(*request.settings(), ValidSettings::new(&settings).unwrap());
        let zero_width = RenderSettings {
            width: 0,
            ..settings
        };
        assert!(ValidSettings::new(&zero_width).is_err());
        let no_view = Camera {
            target: camera.eye,
            ..camera
        };
        let valid = ValidSettings::new(&settings).unwrap();
        assert!(valid.with_camera(&no_view).is_err());
        // A job's own thread count is checked like any setting.
        assert_eq!(request.with_threads(3).unwrap().settings().threads, 3);
        let error = request.with_threads(MLT_MAX_THREADS + 1).unwrap_err();
        assert!(
            error.message.starts_with("settings.threads is"),
            "{error:?}"
        );
    }
}
