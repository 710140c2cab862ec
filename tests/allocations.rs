//! No heap allocation per sample: a render with 10× the samples (and more passes) makes exactly as many
//! allocations. A counting global allocator sees every thread's allocations.

mod common;

use common::*;
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
    let mut image = vec![0.0; 128 * 128 * 3];
    let mut count = |algorithm: Algorithm, spp: u32| {
        let settings = RenderSettings {
            algorithm,
            width: 128,
            height: 128,
            samples_per_pixel: spp,
            threads: 2,
            ..Default::default()
        };
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        render(&scene, &camera, &settings, &mut image, None).unwrap();
        ALLOCATIONS.load(Ordering::SeqCst) - before
    };
    for algorithm in [Algorithm::Path, Algorithm::Bdpt] {
        count(algorithm, 1); // warm up lazily initialized runtime state
        let few = count(algorithm, 2);
        let many = count(algorithm, 20);
        assert!(few > 0, "the counter must see the render's own allocations");
        assert_eq!(
            few, many,
            "{algorithm:?}: 2 spp made {few} allocations, 20 spp made {many}"
        );
    }
}
