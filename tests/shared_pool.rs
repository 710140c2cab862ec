//! Renders from several host threads at once. With `threads` 0 every render runs on one
//! process-wide pool (one thread per core) instead of starting its own, and each still gets
//! exactly the image a render alone gets: four host threads rendering the same scene with
//! four algorithms at once, each in its own order, match the serial renders bit for bit.
//!
//! Runs in under a second on 2 cores (`cargo test --test shared_pool`).

mod common {
    pub mod scenes;
}

use common::scenes::load_canonical;

use mlt::{Algorithm, RenderSettings, render};

fn settings(algorithm: Algorithm) -> RenderSettings {
    RenderSettings {
        width: 32,
        height: 32,
        algorithm,
        samples_per_pixel: 4,
        mutations_per_pixel: 4,
        bootstrap_samples: 4096,
        chains: 64,
        seed: 3,
        threads: 0,
        ..Default::default()
    }
}

const ALGORITHMS: [Algorithm; 4] = [
    Algorithm::Path,
    Algorithm::Bdpt,
    Algorithm::Mmlt,
    Algorithm::PathSpaceMlt,
];

#[test]
fn four_host_threads_rendering_at_once_get_the_serial_images() {
    let (scene, camera) = load_canonical("cornell-glass");
    let render_one = |algorithm: Algorithm| {
        let settings = settings(algorithm);
        let mut image = vec![0.0f32; 32 * 32 * 3];
        let stats = render(&scene, &camera, &settings, &mut image, None).unwrap();
        (image, stats.threads)
    };
    let serial: Vec<(Vec<f32>, u32)> = ALGORITHMS.iter().map(|&a| render_one(a)).collect();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as u32;
    assert!(serial.iter().all(|(_, threads)| *threads == cores));
    assert!(
        serial
            .iter()
            .all(|(image, _)| image.iter().any(|&v| v > 0.0))
    );

    let done = std::sync::atomic::AtomicBool::new(false);
    let (concurrent, most_workers) = std::thread::scope(|s| {
        // How many worker threads exist while the hosts render (Linux names them).
        let monitor = s.spawn(|| {
            let mut most = 0;
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                most = most.max(worker_threads());
                std::thread::sleep(std::time::Duration::from_millis(2));
            }
            most
        });
        let hosts: Vec<_> = (0..4)
            .map(|host| {
                s.spawn(move || {
                    (0..ALGORITHMS.len())
                        .map(|k| {
                            let i = (host + k) % ALGORITHMS.len();
                            (i, render_one(ALGORITHMS[i]).0)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        let images: Vec<Vec<(usize, Vec<f32>)>> =
            hosts.into_iter().map(|h| h.join().unwrap()).collect();
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        (images, monitor.join().unwrap())
    });
    if cfg!(target_os = "linux") {
        // One pool for all: never more workers than cores, and it outlives the renders
        // (pools of their own would have come and gone with each render).
        assert!(
            most_workers <= cores as usize,
            "{most_workers} workers on {cores} cores"
        );
        assert_eq!(worker_threads(), cores as usize);
    }
    for (host, images) in concurrent.iter().enumerate() {
        for (i, image) in images {
            let same = image
                .iter()
                .zip(&serial[*i].0)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(
                same,
                "host {host}: {:?} differs from its serial render",
                ALGORITHMS[*i]
            );
        }
    }
}

/// The process's threads named as mlt's workers (0 where /proc is not there).
fn worker_threads() -> usize {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    tasks
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("comm")).ok())
        .filter(|name| name.starts_with("mlt-worker-"))
        .count()
}
