//! Metropolis light transport: Markov chains whose states are light paths (or the random
//! numbers that generate them), accepted with the Metropolis–Hastings rule.

pub(crate) mod direct_pass;
pub mod driver;
// The textbook example of Metropolis sampling, for the tests and the example that show the
// shared acceptance rule converges.
#[cfg(any(test, feature = "internals"))]
pub mod image_chain;
pub mod normalization;
pub mod path_space;
pub mod primary_space;
pub mod pss;
pub mod pssmlt;
pub mod targets;

/// Metropolis–Hastings acceptance probability of moving from state x to proposal y:
/// min(1, f(y)·T(y→x) / (f(x)·T(x→y))), where `f_current` = f(x), `f_proposal` = f(y) are
/// the scalar target values (luminance of the path contribution) and `transfer_ratio` is
/// T(y→x) / T(x→y) (1 for symmetric mutations). A current state of zero value is always
/// left (chains may start there only by accident).
#[inline]
pub fn acceptance(f_current: f32, f_proposal: f32, transfer_ratio: f32) -> f32 {
    let proposal_possible = f_proposal > 0.0 && transfer_ratio > 0.0;
    if !proposal_possible {
        return 0.0;
    }
    if f_current.is_nan() || f_current <= 0.0 {
        return 1.0;
    }
    (f_proposal * transfer_ratio / f_current).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acceptance_rule() {
        assert_eq!(acceptance(1.0, 2.0, 1.0), 1.0);
        assert_eq!(acceptance(2.0, 1.0, 1.0), 0.5);
        assert_eq!(acceptance(2.0, 1.0, 0.5), 0.25);
        assert_eq!(acceptance(0.0, 1.0, 1.0), 1.0);
        assert_eq!(acceptance(1.0, 0.0, 1.0), 0.0);
        assert_eq!(acceptance(1.0, f32::NAN, 1.0), 0.0);
    }
}
