//! What a render's workers and its calling thread share: the stop and cancel flags, the
//! deadline, and the counters that progress and the statistics are made of.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// Shared state between a render's workers and its calling thread.
pub(crate) struct Control {
    /// Set when workers should finish their current band and start no more.
    stop: AtomicBool,
    cancelled: AtomicBool,
    deadline: Option<Instant>,
    pub(crate) samples_done: AtomicU64,
    pub(crate) mutations_done: AtomicU64,
    pub(crate) rays: AtomicU64,
    pub(crate) invalid: AtomicU64,
    /// Whether progress counts mutations (Metropolis) or camera samples only (ERPT, whose
    /// mutations per sample are not known in advance).
    mutations_are_work: bool,
}

impl Control {
    /// A render's control: `deadline` is when its time limit ends; `mutations_are_work`
    /// whether its progress counts chain mutations (Metropolis) besides camera samples.
    pub(crate) fn new(deadline: Option<Instant>, mutations_are_work: bool) -> Self {
        Control {
            stop: AtomicBool::new(false),
            cancelled: AtomicBool::new(false),
            deadline,
            samples_done: AtomicU64::new(0),
            mutations_done: AtomicU64::new(0),
            rays: AtomicU64::new(0),
            invalid: AtomicU64::new(0),
            mutations_are_work,
        }
    }

    /// Asks the workers to finish their current unit of work and start no more.
    pub(crate) fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Stops the render because the host asked to.
    pub(crate) fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
        self.stop();
    }

    pub(crate) fn was_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }

    pub(crate) fn should_stop(&self) -> bool {
        if self.stop.load(Ordering::Relaxed) {
            return true;
        }
        if self.deadline.is_some_and(|d| Instant::now() >= d) {
            self.stop.store(true, Ordering::Relaxed);
            return true;
        }
        false
    }

    /// Camera samples and mutations: the units of a render's plan.
    pub(crate) fn work_done(&self) -> u64 {
        let mutations = if self.mutations_are_work {
            self.mutations_done.load(Ordering::Relaxed)
        } else {
            0
        };
        self.samples_done.load(Ordering::Relaxed) + mutations
    }

    /// Fraction done: by samples when a count was asked for, else by time.
    pub(crate) fn fraction(&self, planned: u64, start: Instant) -> f32 {
        let by_samples = if planned > 0 {
            self.work_done() as f64 / planned as f64
        } else {
            0.0
        };
        let by_time = self.deadline.map_or(0.0, |d| {
            let total = (d - start).as_secs_f64();
            start.elapsed().as_secs_f64() / total
        });
        by_samples.max(by_time).clamp(0.0, 1.0) as f32
    }
}

/// Which of a render's work units a run does: those whose index is `index` modulo `count`
/// (a job of a render split across machines, `jobs`). The units are fixed by the render's
/// settings, never by the number of jobs, so any split adds up to the same work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct JobShare {
    pub index: u32,
    pub count: u32,
}

impl JobShare {
    /// The whole render, in one run.
    pub const WHOLE: JobShare = JobShare { index: 0, count: 1 };

    #[inline]
    pub fn owns(&self, unit: u64) -> bool {
        unit % self.count as u64 == self.index as u64
    }
}
