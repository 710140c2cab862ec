//! A render split into jobs (`mlt::jobs`): the merged image has the bits of the render one
//! machine makes, for any number of jobs, any thread count per job and any order of the
//! partial results; buffers that are corrupted, truncated, from another plan or another
//! scene are refused.
//!
//! Runs in about 1 s on 2 cores (`cargo test --test jobs`).

mod common {
    pub mod scenes;
    pub mod stats;
}

use common::scenes::{cornell_box, furnace_camera, furnace_scene, furnace_truth, load_canonical};
use common::stats::{assert_within_and_sharp, mean_and_standard_error};

use mlt::jobs::{self, PartialRender, RenderPlan};
use mlt::{Algorithm, MltStatus, RenderSettings, StopReason};

fn settings(algorithm: Algorithm) -> RenderSettings {
    RenderSettings {
        // 11 bands of 4 rows, the last one short.
        width: 24,
        height: 42,
        algorithm,
        samples_per_pixel: 3,
        // Metropolis: 13 chains, so that jobs hold unequal numbers of them, with the direct
        // pass and the normalization pass on (MMLT's pass joins the image).
        mutations_per_pixel: 4,
        bootstrap_samples: 4096,
        chains: 13,
        normalization_work_fraction: 0.2,
        seed: 5,
        threads: 2,
        ..Default::default()
    }
}

/// Plans, renders `jobs` jobs (each through bytes, alternating 1 and 2 threads) and merges
/// them in reverse order.
fn split_render(
    scene: &mlt::Scene,
    camera: &mlt::Camera,
    settings: &RenderSettings,
    count: u32,
) -> (Vec<f32>, mlt::RenderStats) {
    let plan = jobs::plan(scene, camera, settings).unwrap();
    let plan = RenderPlan::from_bytes(&plan.to_bytes()).unwrap();
    let partials: Vec<Vec<u8>> = (0..count)
        .map(|job| {
            let threads = 1 + job % 2;
            let partial = jobs::render_job(scene, &plan, job, count, threads, None).unwrap();
            assert_eq!(partial.stats().stop, StopReason::Completed);
            partial.to_bytes()
        })
        .collect();
    let mut image = vec![0.0f32; settings.output_len().unwrap()];
    let stats = jobs::merge(
        &plan,
        partials
            .iter()
            .rev()
            .map(|bytes| PartialRender::from_bytes(bytes).unwrap()),
        &mut image,
    )
    .unwrap();
    (image, stats)
}

fn same_bits(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn split_renders_merge_into_the_bits_of_one() {
    // Every algorithm, with the options that change how its work is organized.
    let (scene, camera) = load_canonical("cornell-box");
    let filtered = |algorithm| RenderSettings {
        filter_buffers: 4,
        ..settings(algorithm)
    };
    let no_direct_pass = |algorithm| RenderSettings {
        direct_samples_per_mutation: 0,
        ..settings(algorithm)
    };
    for settings in [
        settings(Algorithm::Path),
        settings(Algorithm::Bdpt),
        settings(Algorithm::Pssmlt),
        settings(Algorithm::Mmlt),
        settings(Algorithm::PssmltBdpt),
        filtered(Algorithm::Mmlt),
        no_direct_pass(Algorithm::Pssmlt),
        no_direct_pass(Algorithm::Mmlt),
        settings(Algorithm::Erpt),
        filtered(Algorithm::Erpt),
        settings(Algorithm::PathSpaceMlt),
        RenderSettings {
            adapt_mutation_weights: true,
            ..settings(Algorithm::PathSpaceMlt)
        },
    ] {
        let algorithm = settings.algorithm;
        let mut whole = vec![0.0f32; settings.output_len().unwrap()];
        let stats = mlt::render(&scene, &camera, &settings, &mut whole, None).unwrap();
        assert!(whole.iter().any(|&v| v > 0.0));
        // One job, fewer jobs than bands, and more (some jobs then render nothing).
        for count in [1, 2, 3, 5, 13] {
            let (merged, merged_stats) = split_render(&scene, &camera, &settings, count);
            assert!(
                same_bits(&whole, &merged),
                "{algorithm:?} in {count} jobs differs from one render"
            );
            assert_eq!(merged_stats.samples, stats.samples);
            assert_eq!(merged_stats.mutations, stats.mutations);
            assert_eq!(merged_stats.accepted_mutations, stats.accepted_mutations);
            assert_eq!(merged_stats.mutation_counts, stats.mutation_counts);
            assert_eq!(merged_stats.mutation_weights, stats.mutation_weights);
            if matches!(algorithm, Algorithm::Path | Algorithm::Bdpt) {
                // Every ERPT job runs the pre-pass of its deposit energy, every Metropolis
                // job the calibration of its normalization pass.
                assert_eq!(merged_stats.rays, stats.rays);
            }
            assert_eq!(merged_stats.stop, StopReason::Completed);
            assert_eq!(merged_stats.normalization, stats.normalization);
            assert_eq!(merged_stats.filter, stats.filter);
        }
    }
}

/// Asserts that `result` is an invalid-argument error whose message contains `needle`.
fn invalid<T>(result: Result<T, mlt::Error>, needle: &str) {
    match result {
        Ok(_) => panic!("accepted; expected an error about {needle:?}"),
        Err(e) => {
            assert_eq!(
                e.status,
                MltStatus::MLT_STATUS_INVALID_ARGUMENT,
                "{}",
                e.message
            );
            assert!(
                e.message.contains(needle),
                "{:?} lacks {needle:?}",
                e.message
            );
        }
    }
}

#[test]
fn bad_buffers_jobs_and_scenes_are_refused() {
    let (scene, camera) = load_canonical("cornell-box");
    let settings = settings(Algorithm::Path);
    let plan = jobs::plan(&scene, &camera, &settings).unwrap();
    let plan_bytes = plan.to_bytes();
    // A flipped bit anywhere, or a buffer cut short, is caught by the checksum or frame.
    let mut flipped = plan_bytes.clone();
    flipped[plan_bytes.len() / 2] ^= 4;
    invalid(RenderPlan::from_bytes(&flipped), "corrupted");
    invalid(
        RenderPlan::from_bytes(&plan_bytes[..plan_bytes.len() - 1]),
        "truncated",
    );
    invalid(
        RenderPlan::from_bytes(b"not a plan"),
        "not an mlt render plan",
    );

    let job = |k: u32, n: u32| jobs::render_job(&scene, &plan, k, n, 1, None).unwrap();
    let partial = job(0, 2).to_bytes();
    invalid(
        PartialRender::from_bytes(&plan_bytes),
        "not an mlt partial render",
    );
    let mut flipped = partial.clone();
    flipped[40] ^= 1;
    invalid(PartialRender::from_bytes(&flipped), "corrupted");

    invalid(jobs::render_job(&scene, &plan, 2, 2, 1, None), "job 2");
    invalid(jobs::render_job(&scene, &plan, 0, 0, 1, None), "jobs is 0");
    // A scene built from other arrays (one vertex moved) is not the plan's.
    let mut mesh = cornell_box();
    mesh.positions[0] += 1e-3;
    invalid(
        jobs::render_job(&mesh.scene(), &plan, 0, 1, 1, None),
        "not the one the plan was made for",
    );

    let mut image = vec![0.0f32; settings.output_len().unwrap()];
    let mut merge = |partials: Vec<PartialRender>, plan: &RenderPlan| {
        jobs::merge(plan, partials, &mut image).map(|_| ())
    };
    invalid(merge(vec![job(1, 2)], &plan), "missing");
    invalid(merge(vec![job(0, 2), job(0, 2)], &plan), "given twice");
    invalid(merge(vec![job(0, 2), job(1, 3)], &plan), "split one way");
    invalid(merge(Vec::new(), &plan), "no partial render");
    let other_seed = RenderSettings {
        seed: 6,
        ..settings
    };
    let other_plan = jobs::plan(&scene, &camera, &other_seed).unwrap();
    invalid(merge(vec![job(0, 1)], &other_plan), "another plan");
}

/// A job cut short (here cancelled after its first round; a time limit stops it the same
/// way) still merges into a correctly normalized image: its chains' work is scaled up to the
/// mutations planned. In the furnace every pixel's radiance is known.
#[test]
fn a_job_cut_short_still_merges_into_the_right_brightness() {
    let (albedo, emission) = ([0.5; 3], [1.0; 3]);
    let scene = furnace_scene(albedo, emission);
    let settings = RenderSettings {
        width: 32,
        height: 32,
        algorithm: Algorithm::Mmlt,
        mutations_per_pixel: 512,
        bootstrap_samples: 1 << 14,
        chains: 64,
        seed: 3,
        ..Default::default()
    };
    let plan = jobs::plan(&scene, &furnace_camera(), &settings).unwrap();
    let mut stop_at_once = |_: f32| false;
    let cut = jobs::render_job(&scene, &plan, 0, 2, 1, Some(&mut stop_at_once)).unwrap();
    assert_eq!(cut.stats().stop, StopReason::Cancelled);
    let whole = jobs::render_job(&scene, &plan, 1, 2, 1, None).unwrap();
    assert!(
        cut.stats().mutations < whole.stats().mutations / 4,
        "the job was not cut: {} mutations against {}",
        cut.stats().mutations,
        whole.stats().mutations
    );
    let (cut, whole) = (cut.to_bytes(), whole.to_bytes());
    let mut images = [cut.clone(), whole.clone()].map(|_| vec![0.0f32; 32 * 32 * 3]);
    for (order, image) in [[&cut, &whole], [&whole, &cut]].iter().zip(&mut images) {
        let partials = order.map(|b| PartialRender::from_bytes(b).unwrap());
        let stats = jobs::merge(&plan, partials, image).unwrap();
        assert_eq!(stats.stop, StopReason::Cancelled);
    }
    assert!(
        same_bits(&images[0], &images[1]),
        "the merge depends on the order"
    );
    let truth = furnace_truth(albedo, emission, settings.max_depth)[0];
    let (mean, error) = mean_and_standard_error(&images[0]);
    assert_within_and_sharp("cut merge, red", mean[0], truth, error[0], 4.0);
}

/// Partial results combined in a tree (some in twos, one alone, one combination combined
/// again), through bytes and in shuffled order, merge into the bits of the whole render, and
/// a combination names the jobs it holds.
#[test]
fn combined_partial_results_merge_into_the_same_bits() {
    let (scene, camera) = load_canonical("cornell-box");
    for settings in [
        settings(Algorithm::Path),
        settings(Algorithm::Mmlt),
        RenderSettings {
            filter_buffers: 4,
            ..settings(Algorithm::Pssmlt)
        },
        settings(Algorithm::PathSpaceMlt),
        settings(Algorithm::Erpt),
    ] {
        let algorithm = settings.algorithm;
        let mut whole = vec![0.0f32; settings.output_len().unwrap()];
        let stats = mlt::render(&scene, &camera, &settings, &mut whole, None).unwrap();
        let plan = jobs::plan(&scene, &camera, &settings).unwrap();
        let count = 7;
        let partials: Vec<Vec<u8>> = (0..count)
            .map(|job| {
                jobs::render_job(&scene, &plan, job, count, 1, None)
                    .unwrap()
                    .to_bytes()
            })
            .collect();
        let decode = |job: usize| PartialRender::from_bytes(&partials[job]).unwrap();
        let combine = |parts: Vec<PartialRender>| {
            let combined = jobs::combine(&plan, parts).unwrap();
            PartialRender::from_bytes(&combined.to_bytes()).unwrap()
        };
        let pair = combine(vec![decode(3), decode(0)]);
        assert_eq!(pair.held_jobs(), [0, 3]);
        assert_eq!(pair.job(), 0);
        assert_eq!(pair.name(), "jobs [0, 3] of 7");
        let alone = combine(vec![decode(5)]);
        assert_eq!(alone.held_jobs(), [5]);
        let trio = combine(vec![decode(6), decode(1), decode(2)]);
        let pair_and_alone = combine(vec![alone, pair]);
        assert_eq!(pair_and_alone.held_jobs(), [0, 3, 5]);
        let mut merged = vec![0.0f32; whole.len()];
        let merged_stats =
            jobs::merge(&plan, [trio, decode(4), pair_and_alone], &mut merged).unwrap();
        assert!(
            same_bits(&whole, &merged),
            "{algorithm:?}: the combined jobs differ from one render"
        );
        assert_eq!(merged_stats.samples, stats.samples);
        assert_eq!(merged_stats.mutations, stats.mutations);
        assert_eq!(merged_stats.normalization, stats.normalization);
        assert_eq!(merged_stats.filter, stats.filter);
    }
}

#[test]
fn combining_a_job_twice_or_from_another_plan_is_refused() {
    let (scene, camera) = load_canonical("cornell-box");
    let settings = settings(Algorithm::Mmlt);
    let plan = jobs::plan(&scene, &camera, &settings).unwrap();
    let job = |k: u32| jobs::render_job(&scene, &plan, k, 3, 1, None).unwrap();
    let pair = jobs::combine(&plan, [job(0), job(1)]).unwrap();
    invalid(
        jobs::combine(&plan, [pair.clone(), job(1)]),
        "job 1 of 3 is given twice",
    );
    invalid(
        jobs::combine(&plan, Vec::<PartialRender>::new()),
        "no partial render",
    );
    let other_plan = jobs::plan(
        &scene,
        &camera,
        &RenderSettings {
            seed: 6,
            ..settings
        },
    )
    .unwrap();
    invalid(jobs::combine(&other_plan, [job(2)]), "another plan");
    let mut image = vec![0.0f32; settings.output_len().unwrap()];
    invalid(
        jobs::merge(&plan, [pair], &mut image),
        "jobs [2] of 3 are missing",
    );
}
