//! No heap allocation per sample or mutation: a render with 10× the samples makes as many
//! allocations, up to the scheduling noise of rayon's internals (see below). A counting global
//! allocator sees every thread's allocations.
//!
//! Runs in about 2 s on 2 cores (`cargo test --test allocations`).

mod common {
    pub mod scenes;
}

use common::scenes::{furnace_camera, furnace_scene};

use mlt::{Algorithm, RenderSettings, render};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

struct CountingAllocator;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

// SAFETY: forwards to the system allocator unchanged; only counts calls.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn allocations_do_not_grow_with_samples() {
    let scene = furnace_scene([0.5; 3], [1.0; 3]);
    let camera = furnace_camera();
    let mut image = vec![0.0; 32 * 32 * 3];
    // `options`: path-space MLT's and ERPT's adapted weights and sample-space perturbations,
    // and the post-process filter (which allocates once per render, after the sampling).
    let mut count = |(algorithm, options): (Algorithm, bool), per_pixel: u32| {
        let settings = RenderSettings {
            algorithm,
            adapt_mutation_weights: options,
            perturb_in_sample_space: options,
            filter_buffers: if options { 4 } else { 0 },
            width: 32,
            height: 32,
            samples_per_pixel: per_pixel,
            mutations_per_pixel: per_pixel,
            bootstrap_samples: 4096,
            chains: 64,
            threads: 2,
            max_depth: 3,
            ..Default::default()
        };
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        render(&scene, &camera, &settings, &mut image, None).unwrap();
        ALLOCATIONS.load(Ordering::SeqCst) - before
    };
    for algorithm in [
        (Algorithm::Path, false),
        (Algorithm::Bdpt, false),
        (Algorithm::Pssmlt, false),
        (Algorithm::Pssmlt, true),
        (Algorithm::PssmltBdpt, false),
        (Algorithm::Mmlt, false),
        (Algorithm::PathSpaceMlt, false),
        (Algorithm::PathSpaceMlt, true),
        (Algorithm::Erpt, false),
        (Algorithm::Erpt, true),
    ] {
        // 32 x 32 pixels: both renders take the same number of passes (one sample, then up
        // to 64 per pass) and rounds, so only per-sample allocations could differ.
        count(algorithm, 1); // warm up lazily initialized runtime state
        // Rayon's work-stealing deques retire buffers through crossbeam-epoch, which
        // allocates 2 KiB garbage bags depending on scheduling: a render's count varies by
        // a couple either way. The fewest over a few renders, compared with a slack of 2,
        // still catches any per-sample allocation (18,432 more samples here).
        let mut fewest = |per_pixel| (0..3).map(|_| count(algorithm, per_pixel)).min().unwrap();
        let few = fewest(2);
        let many = fewest(20);
        assert!(few > 0, "the counter must see the render's own allocations");
        assert!(
            many.abs_diff(few) <= 2,
            "{algorithm:?}: 2 samples (or mutations) per pixel made {few} allocations, 20 made {many}"
        );
    }
}
