//! What a render reports.

use crate::filter::FilterStats;
use crate::integrators::mlt::driver::{MutationCounts, MutationWeights};
use crate::integrators::mlt::normalization::NormalizationStats;
/// Why a render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    Completed,
    Cancelled,
    TimeLimitReached,
}

/// What a render did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderStats {
    pub stop: StopReason,
    /// Camera samples taken over the whole image (path tracing, BDPT, a Metropolis render's
    /// direct pass).
    pub samples: u64,
    /// Metropolis: mutations made by all chains.
    pub mutations: u64,
    /// Rays traced (closest-hit and shadow).
    pub rays: u64,
    /// Samples whose radiance was not finite and were dropped (counted in `samples`).
    pub invalid_samples: u64,
    pub seconds: f64,
    pub threads: u32,
    /// Metropolis: accepted mutations.
    pub accepted_mutations: u64,
    /// Metropolis: the normalization b = ∫ luminance(f) the image was scaled by (its final
    /// estimate), how many independent samples it came from, its estimated relative
    /// standard error and the largest share of it one sample carried. ERPT: `value` is the
    /// deposit energy e_d the chains used.
    pub normalization: NormalizationStats,
    /// Path-space MLT: proposals and acceptances per mutation …
    pub mutation_counts: MutationCounts,
    /// … and the weights the chains ran with (after the warm-up, if adapted). ERPT: the
    /// weights of its perturbations.
    pub mutation_weights: MutationWeights,
    /// What the post-process filter did (zeros when it is off).
    pub filter: FilterStats,
}
