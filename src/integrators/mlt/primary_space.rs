//! Primary sample space: the function of the primary samples a chain of Kelemen's kind
//! explores (`PrimarySpaceTarget`: PSSMLT over the path tracer, over BDPT, MMLT), the state a
//! chain deposits (`PathSample`), the settings every Metropolis render shares and the sampler
//! they start from.

use super::pss::PssSampler;
use crate::film::Splat;
use crate::scene::CameraModel;
use crate::spectrum::Spectrum;

/// The settings every Metropolis render's chains share (`RenderSettings` documents each).
#[derive(Clone, Copy, Debug)]
pub struct MetropolisSettings {
    pub mutations_per_pixel: u32,
    pub bootstrap_samples: u32,
    pub chains: u32,
    pub large_step_probability: f32,
    pub small_step_sigma: f32,
    /// The share of the rays the normalization pass spends (`normalization` module).
    pub normalization_work_fraction: f32,
    pub seed: u64,
    /// The chains this run makes: all, or a job's share of a split render (chain c is job
    /// c mod N's).
    pub(crate) share: crate::control::JobShare,
}

/// What one state of a chain contributes to the image: a few (pixel, value) entries and the
/// scalar target f the chain is distributed by.
pub(crate) struct PathSample {
    pub entries: Vec<Splat>,
    pub target: f32,
}

impl PathSample {
    pub fn with_capacity(entries: usize) -> Self {
        PathSample {
            entries: Vec::with_capacity(entries),
            target: 0.0,
        }
    }

    pub fn clear(&mut self) {
        self.entries.clear();
        self.target = 0.0;
    }

    /// The luminance of a contribution, or 0 for one that is not finite or not positive
    /// (dropped: a chain must not be drawn to a NaN).
    #[inline]
    pub fn usable_luminance(value: Spectrum) -> f32 {
        let luminance = value.luminance();
        if luminance > 0.0 && luminance.is_finite() && value.is_finite() {
            luminance
        } else {
            0.0
        }
    }

    /// Adds a contribution; non-finite or black ones are dropped.
    #[inline]
    pub fn push(&mut self, pixel: u32, value: Spectrum) {
        let luminance = Self::usable_luminance(value);
        if luminance > 0.0 {
            self.entries.push(Splat::new(pixel, value));
            self.target += luminance;
        }
    }
}

/// A function over primary sample space whose luminance the chains are distributed by.
pub(crate) trait PrimarySpaceTarget: Sync {
    type Scratch: Send;
    fn scratch(&self) -> Self::Scratch;
    /// Streams the sampler interleaves (see `Sampler::start_stream`).
    fn streams(&self) -> usize;
    /// Most coordinates one evaluation reads.
    fn dimensions(&self) -> usize;
    /// Most entries of one `PathSample`.
    fn max_entries(&self) -> usize;
    /// Groups with separate chains and normalizations (MMLT: path depths).
    fn groups(&self) -> usize;
    /// Evaluates an independent sample, adding each group's target value to `targets`.
    fn bootstrap(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut Self::Scratch,
        targets: &mut [f32],
        rays: &mut u64,
    );
    /// `bootstrap`, also handing each *point* of the sample to `point(group, state)`: a state
    /// a chain of that group could be in, with its value and its contributions as the chain
    /// would deposit them, so that the normalization pass's samples can join the image
    /// (`NormalizationPass::with_image`).
    #[allow(clippy::too_many_arguments)]
    fn pass_sample(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut Self::Scratch,
        targets: &mut [f32],
        rays: &mut u64,
        point: &mut dyn FnMut(usize, &PathSample),
    );
    /// Whether the normalization pass's samples join the image (`PassImage`): measured to
    /// pay for MMLT, whose pass samples (every strategy of every depth) render the dim
    /// parts its single-strategy large steps find poorly; for PSSMLT over the path tracer
    /// without the direct pass they added noise to the image mean.
    fn pass_joins_the_image(&self) -> bool {
        false
    }
    /// Points of `group` a pass sample has: where the bootstrap sums alternatives that a
    /// chain's state picks one of (MMLT: the strategies of a depth), a point per alternative,
    /// one in each stratum of the coordinate that picks it.
    fn points_per_sample(&self, _group: usize) -> u32 {
        1
    }
    /// Evaluates the state a chain of `group` starts from: the sampler was restarted where
    /// a bootstrap sample was drawn. Where the bootstrap summed alternatives the chain state
    /// picks one of (MMLT: strategies), `choice` ∈ [0, 1) picks one in proportion to its value
    /// and the sampler is changed to hold it.
    #[allow(clippy::too_many_arguments)]
    fn seed(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut Self::Scratch,
        group: usize,
        choice: f32,
        out: &mut PathSample,
        rays: &mut u64,
    );
    /// Whether a large step's proposal is what `bootstrap` evaluates (the sum over the
    /// single group) and pooling it with the stratified samples helps, so that it also
    /// estimates the normalization.
    fn large_steps_are_bootstrap_samples(&self) -> bool {
        false
    }
    /// Evaluates the sampler's current state for a chain of `group`.
    fn evaluate(
        &self,
        camera: &CameraModel,
        sampler: &mut PssSampler,
        scratch: &mut Self::Scratch,
        group: usize,
        out: &mut PathSample,
        rays: &mut u64,
    );
}

/// The film position of a primary sample pair, in pixels, and its pixel index.
#[inline]
pub(crate) fn film_position(camera: &CameraModel, [u, v]: [f32; 2]) -> (f32, f32, u32) {
    let (width, height) = (camera.width as f32, camera.height as f32);
    // u < 1, but u · width can round up to width itself.
    let x = (u * width).min(width.next_down());
    let y = (v * height).min(height.next_down());
    (x, y, y as u32 * camera.width + x as u32)
}

/// A sampler laid out for `target` with the chains' step settings; each use restarts it
/// (`restart_as_bootstrap`) before its first sample.
pub(crate) fn new_sampler<T: PrimarySpaceTarget>(
    target: &T,
    settings: &MetropolisSettings,
) -> PssSampler {
    PssSampler::new(
        settings.seed,
        0,
        settings.large_step_probability,
        settings.small_step_sigma,
        target.streams(),
        target.dimensions(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn film_positions_keep_their_place_within_the_last_pixel() {
        // The last column and row once had every position clamped to their pixel's corner.
        let camera = crate::scene::Camera::default().model(4, 2);
        assert_eq!(film_position(&camera, [0.9, 0.75]), (3.6, 1.5, 7));
        assert_eq!(film_position(&camera, [0.1, 0.25]), (0.4, 0.5, 0));
        let (x, y, pixel) = film_position(&camera, [1.0f32.next_down(), 1.0f32.next_down()]);
        assert!(x < 4.0 && y < 2.0 && pixel == 7, "{x} {y} {pixel}");
    }
}
