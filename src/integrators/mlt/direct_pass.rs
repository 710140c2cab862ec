//! A Metropolis render's direct pass (`RenderSettings::direct_samples_per_mutation`): camera
//! samples of the path tracer for the shortest paths, which the chains render poorly. It
//! keeps pace with the chains: it takes its first pass before they start, and after each
//! round of mutations catches up to its samples per mutation, so a render stopped early
//! keeps the ratio.

use crate::control::{Control, JobShare};
use crate::film::Film;
use crate::integrators::camera_samples::CameraSamplePasses;
use crate::integrators::path::PathTracer;
use crate::scene::CameraModel;

pub(crate) struct DirectPass<'a> {
    samples: CameraSamplePasses<'a, PathTracer<'a>>,
    samples_per_mutation: u32,
}

impl<'a> DirectPass<'a> {
    /// Starts the pass of `share` of a render of `mutations_per_pixel` (0: until stopped)
    /// with its first pass, one sample per pixel, which always runs to its end.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn start(
        tracer: &'a PathTracer<'a>,
        camera: &CameraModel,
        seed: u64,
        samples_per_mutation: u32,
        mutations_per_pixel: u32,
        share: JobShare,
        film: &mut Film,
        control: &Control,
    ) -> Self {
        let total = samples_per_mutation * mutations_per_pixel;
        let mut samples =
            CameraSamplePasses::new(tracer, camera, seed, total, film).with_share(share);
        samples.run_until(film, control, 1);
        DirectPass {
            samples,
            samples_per_mutation,
        }
    }

    /// Catches up with chains that have made `mutations_per_pixel` so far.
    pub(crate) fn keep_pace(
        &mut self,
        film: &mut Film,
        control: &Control,
        mutations_per_pixel: f64,
    ) {
        let target = (self.samples_per_mutation as f64 * mutations_per_pixel)
            .ceil()
            .min(u32::MAX as f64);
        self.samples.run_until(film, control, target as u32);
    }
}
