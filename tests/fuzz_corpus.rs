//! The fuzzers' smoke run: every committed corpus input and regression input of each fuzz
//! target (`fuzz/corpus/TARGET/`, `fuzz/regressions/TARGET/`) replayed through the target's
//! own body (`fuzz/src/targets.rs`, included here, so there is one copy of each). An input
//! fails the test by panicking (the bodies assert what the library promises) or by taking
//! longer than `SLOWEST`; each regression input once crashed, hung or panicked the library.
//!
//! Runs in under a second on 2 cores (`cargo test --test fuzz_corpus`).

#[path = "../fuzz/src/targets.rs"]
mod targets;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The longest one input may take. A fuzzer execution takes about a millisecond; this is
/// far above it, so only a hang (or a pathological slowdown) fails.
const SLOWEST: Duration = Duration::from_secs(2);

fn inputs(target: &str) -> Vec<PathBuf> {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut files: Vec<PathBuf> = ["corpus", "regressions"]
        .iter()
        .map(|kind| fuzz.join(kind).join(target))
        .filter(|dir| dir.is_dir())
        .flat_map(|dir| std::fs::read_dir(dir).expect("a readable directory"))
        .map(|entry| entry.expect("a readable entry").path())
        .filter(|path| path.is_file())
        .collect();
    files.sort();
    files
}

fn replay(target: &str, body: fn(&[u8])) {
    let files = inputs(target);
    assert!(!files.is_empty(), "no corpus for the fuzz target {target}");
    for file in &files {
        let bytes = std::fs::read(file).expect("a readable input");
        let start = Instant::now();
        // A panic names the input: the body's own message comes first.
        let result = std::panic::catch_unwind(|| body(&bytes));
        let elapsed = start.elapsed();
        assert!(
            result.is_ok(),
            "{target} panicked on {} (replay it with `cargo +nightly fuzz run {target} {}`)",
            file.display(),
            file.display()
        );
        assert!(
            elapsed <= SLOWEST,
            "{target} took {elapsed:?} on {}, more than {SLOWEST:?}",
            file.display()
        );
    }
    let _ = std::fs::remove_dir_all(targets::scratch_dir());
}

#[test]
fn capi_scene() {
    replay("capi_scene", targets::capi_scene);
}

#[test]
fn ray_queries() {
    replay("ray_queries", targets::ray_queries);
}

#[test]
fn obj_mtl() {
    replay("obj_mtl", targets::obj_mtl);
}

#[test]
fn gltf_glb() {
    replay("gltf_glb", targets::gltf_glb);
}

#[test]
fn camera_file() {
    replay("camera_file", targets::camera_file);
}
