//! The `mlt-render` command line end to end: small renders with each algorithm's flags and
//! the summary they print, the filter and time-limit flags, the lights' flags (an
//! environment map, a constant sky, a sun) lighting a quad as bright as they should, a scene
//! without a camera framed and its camera printed, and every bad input, one table of them, a
//! one-line error naming what is wrong.
//!
//! Runs in under a second on 2 cores (`cargo test --test cli`).
#![cfg(feature = "cli")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/scenes")
        .join(name)
}

fn temp_path(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("mlt-cli-test-{}-{n}-{name}", std::process::id()))
}

fn mlt_render(args: &[&dyn AsRef<std::ffi::OsStr>]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mlt-render"))
        .args(args.iter().map(|a| a.as_ref()))
        .output()
        .expect("mlt-render runs")
}

/// Every line of a render summary after the first is a label in one column and its value
/// starting in the next.
fn assert_summary_lines_up(stdout: &str) {
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(lines[0].starts_with("mlt-render: "), "{stdout}");
    for line in &lines[1..] {
        let (label, value) = (&line[..15], &line[15..]);
        assert!(
            label.starts_with("  ") && !label[2..].starts_with(' ') && value.starts_with(' '),
            "{line:?} in:\n{stdout}"
        );
        assert!(!value[1..].starts_with(' '), "{line:?} in:\n{stdout}");
    }
}

/// Whether `output` is exit status 1 and exactly one stderr line `mlt-render: ...`, without a
/// panic, containing each of `needles`: the line, or what is wrong.
fn check_one_line_error(output: &Output, needles: &[&str]) -> Result<String, String> {
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    let lines: Vec<&str> = stderr.lines().collect();
    if output.status.code() != Some(1) {
        return Err(format!(
            "exit status {:?}; stderr: {stderr}",
            output.status.code()
        ));
    }
    if stderr.contains("panicked") || stderr.contains("RUST_BACKTRACE") {
        return Err(format!("a panic: {stderr}"));
    }
    if lines.len() != 1 || !lines[0].starts_with("mlt-render: ") {
        return Err(format!("not one line `mlt-render: ...`: {stderr}"));
    }
    let missing: Vec<&str> = needles
        .iter()
        .copied()
        .filter(|needle| !lines[0].contains(needle))
        .collect();
    if !missing.is_empty() {
        return Err(format!("{:?} should mention {missing:?}", lines[0]));
    }
    Ok(lines[0].to_owned())
}

/// Exit status 1 and exactly one stderr line `mlt-render: ...` without a panic; returns it.
#[track_caller]
fn assert_one_line_error(output: &Output) -> String {
    check_one_line_error(output, &[]).unwrap_or_else(|error| panic!("{error}"))
}

#[test]
fn renders_the_cornell_box_to_pfm_and_prints_a_summary() {
    let out = temp_path("cornell.pfm");
    let output = mlt_render(&[
        &scene("cornell-box.obj"),
        &"--algorithm",
        &"path",
        &"--spp",
        &"2",
        &"--width",
        &"32",
        &"--height",
        &"32",
        &"--threads",
        &"2",
        &"--out",
        &out,
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "stdout: {stdout}\nstderr: {stderr}"
    );
    for needle in [
        "(32 x 32, path, max depth",
        "wall time",
        "samples       2048 (2.00 per pixel)",
        "samples/s",
        "Mrays/s",
        "threads       2",
        "status        completed",
    ] {
        assert!(stdout.contains(needle), "missing {needle:?} in:\n{stdout}");
    }
    assert_summary_lines_up(&stdout);

    let (w, h, rgb) = mlt::io::read_pfm(&out).unwrap();
    assert_eq!((w, h), (32, 32));
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    // Converged means of this view are about (0.19, 0.13, 0.036): the light is (17, 12, 4)
    // and the red and green walls reflect little blue, so blue sits below 0.05. Bound each
    // channel loosely, the sum tighter, and check the channels are not swapped.
    let means: Vec<f32> = (0..3)
        .map(|c| rgb.iter().skip(c).step_by(3).sum::<f32>() / (w * h) as f32)
        .collect();
    for (c, mean) in means.iter().enumerate() {
        assert!((0.01..5.0).contains(mean), "channel {c} mean {mean}");
    }
    let total: f32 = means.iter().sum();
    assert!((0.15..5.0).contains(&total), "means {means:?}");
    assert!(
        means[0] > means[1] && means[1] > means[2],
        "means {means:?}"
    );
    std::fs::remove_file(&out).unwrap();
}

#[test]
fn the_default_algorithm_is_metropolis_and_its_summary_counts_mutations() {
    let out = temp_path("default.pfm");
    let output = mlt_render(&[
        &scene("cornell-box.obj"),
        &"--mutations-per-pixel",
        &"2",
        &"--bootstrap",
        &"4096",
        &"--chains",
        &"64",
        &"--width",
        &"32",
        &"--height",
        &"32",
        &"--out",
        &out,
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{output:?}");
    for needle in [
        // The algorithm as the user names it.
        "(32 x 32, mmlt, max depth",
        // The direct pass: one camera sample per mutation.
        "samples       2048 (2.00 per pixel)",
        "mutations     2048 (2.00 per pixel)",
        "mutations/s",
        "metropolis    b = ",
        "status        completed",
    ] {
        assert!(stdout.contains(needle), "missing {needle:?} in:\n{stdout}");
    }
    assert_summary_lines_up(&stdout);
    let (w, h, rgb) = mlt::io::read_pfm(&out).unwrap();
    assert_eq!((w, h), (32, 32));
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    std::fs::remove_file(&out).unwrap();
}

#[test]
fn path_space_mlt_takes_mutation_weights_and_reports_each_mutation() {
    let out = temp_path("path-space.pfm");
    let output = mlt_render(&[
        &scene("cornell-glass.obj"),
        &"--algorithm",
        &"path-space-mlt",
        &"--mutation-weights",
        &"1,1,1,1",
        &"--mutations-per-pixel",
        &"4",
        &"--bootstrap",
        &"4096",
        &"--chains",
        &"64",
        &"--width",
        &"32",
        &"--height",
        &"32",
        &"--out",
        &out,
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{output:?}");
    let proposed = |name: &str| -> u64 {
        let line = stdout
            .lines()
            .find(|l| l.trim_start().starts_with(name) && l.contains("proposed"))
            .unwrap_or_else(|| panic!("no {name:?} line in:\n{stdout}"));
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    let counts = ["bidirectional", "lens", "caustic", "multichain"].map(proposed);
    // Glass has caustic and multi-chain paths: every mutation is tried, and they add up to
    // the mutations made.
    assert!(counts.iter().all(|&n| n > 0), "{counts:?} in:\n{stdout}");
    assert_eq!(counts.iter().sum::<u64>(), 4 * 32 * 32, "{stdout}");
    std::fs::remove_file(&out).unwrap();
}

/// `--adapt-mutation-weights` reports the weights the chains ran with after the warm-up:
/// on cornell-glass the lens perturbation, accepted far more often than the bidirectional
/// mutation, gains weight on it. `--perturb-in-sample-space` is taken.
#[test]
fn path_space_mlt_adapts_its_mutation_weights_and_reports_them() {
    let out = temp_path("path-space-adapted.pfm");
    let output = mlt_render(&[
        &scene("cornell-glass.obj"),
        &"--algorithm",
        &"path-space-mlt",
        &"--mutation-weights",
        &"1,1,1,1",
        &"--adapt-mutation-weights",
        &"--perturb-in-sample-space",
        &"--mutations-per-pixel",
        &"4",
        &"--bootstrap",
        &"4096",
        &"--chains",
        &"64",
        &"--width",
        &"32",
        &"--height",
        &"32",
        &"--out",
        &out,
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{output:?}");
    let line = |name: &str| -> Vec<String> {
        stdout
            .lines()
            .find(|l| l.trim_start().starts_with(name) && l.contains("proposed"))
            .unwrap_or_else(|| panic!("no {name:?} line in:\n{stdout}"))
            .split_whitespace()
            .map(str::to_owned)
            .collect()
    };
    let weight = |name: &str| -> f32 { line(name).last().unwrap().parse().unwrap() };
    let proposed = |name: &str| -> u64 { line(name)[1].parse().unwrap() };
    let names = ["bidirectional", "lens", "caustic", "multichain"];
    assert_eq!(
        names.map(proposed).iter().sum::<u64>(),
        4 * 32 * 32,
        "{stdout}"
    );
    let weights = names.map(weight);
    assert!(weights[1] > 1.5 * weights[0], "{weights:?} in:\n{stdout}");
    assert!(weights != [1.0; 4], "{stdout}");
    std::fs::remove_file(&out).unwrap();
}

#[test]
fn erpt_takes_its_settings_and_reports_mutations() {
    let out = temp_path("erpt.pfm");
    let output = mlt_render(&[
        &scene("cornell-glass.obj"),
        &"--algorithm",
        &"erpt",
        &"--spp",
        &"2",
        &"--erpt-chain-length",
        &"10",
        &"--erpt-deposit",
        &"0.0005",
        &"--width",
        &"32",
        &"--height",
        &"32",
        &"--out",
        &out,
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{output:?}");
    assert!(stdout.contains("erpt          e_d = 0.000500"), "{stdout}");
    assert_summary_lines_up(&stdout);
    let mutations: u64 = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("mutations "))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no mutations line in:\n{stdout}"));
    // Chains of 10 steps.
    assert!(mutations > 0 && mutations.is_multiple_of(10), "{stdout}");
    let (w, h, rgb) = mlt::io::read_pfm(&out).unwrap();
    assert_eq!((w, h), (32, 32));
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    std::fs::remove_file(&out).unwrap();
}

#[test]
fn time_limit_with_unbounded_samples_completes_at_the_limit_and_says_so() {
    let out = temp_path("timed.png");
    // A 16 x 16 path-traced render of `spp` samples per pixel (0: unbounded) with a time
    // limit of 0.3 s; its summary.
    let timed_render = |spp: &str| -> String {
        let output = mlt_render(&[
            &scene("cornell-box.obj"),
            &"--algorithm",
            &"path",
            &"--spp",
            &spp,
            &"--time-limit",
            &"0.3",
            &"--width",
            &"16",
            &"--height",
            &"16",
            &"--threads",
            &"1",
            &"--out",
            &out,
        ]);
        assert!(output.status.success(), "{output:?}");
        String::from_utf8_lossy(&output.stdout).into_owned()
    };
    // The user asked for exactly that: not "stopped early".
    let stdout = timed_render("0");
    assert!(
        stdout.contains("status        completed at the time limit of 0.3 s"),
        "{stdout}"
    );
    let image = image::open(&out).unwrap();
    assert_eq!((image.width(), image.height()), (16, 16));

    // A sample count the time limit cuts short is stopping early.
    let stdout = timed_render("1000000");
    assert!(
        stdout.contains("status        stopped early: time limit of 0.3 s reached"),
        "{stdout}"
    );
    std::fs::remove_file(&out).unwrap();
}

/// `--backend embree` renders in builds with the `embree` feature and is a one-line error
/// naming the feature in builds without.
#[test]
fn embree_backend_renders_or_names_the_missing_feature() {
    let out = temp_path("embree.pfm");
    let output = mlt_render(&[
        &scene("cornell-box.obj"),
        &"--backend",
        &"embree",
        &"--spp",
        &"1",
        &"--width",
        &"8",
        &"--height",
        &"8",
        &"--out",
        &out,
    ]);
    if cfg!(feature = "embree") {
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(output.status.success(), "{output:?}");
        assert!(stdout.contains("embree backend"), "{stdout}");
        let (w, h, _) = mlt::io::read_pfm(&out).unwrap();
        assert_eq!((w, h), (8, 8));
        let _ = std::fs::remove_file(&out);
    } else {
        let line = assert_one_line_error(&output);
        assert!(line.contains("unsupported"), "{line}");
        assert!(line.contains("`embree` feature"), "{line}");
    }
}

/// `--build-quality` reaches the scene (the summary names it, with the build's time and
/// memory), and the default is `high`.
#[test]
fn build_quality_is_applied_and_reported() {
    for (flag, expected) in [(None, "high build"), (Some("fast"), "fast build")] {
        let out = temp_path(&format!("quality-{expected}.pfm"));
        let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![
            &"--algorithm",
            &"path",
            &"--spp",
            &"1",
            &"--width",
            &"8",
            &"--height",
            &"8",
            &"--out",
            &out,
        ];
        let scene_path = scene("cornell-box.obj");
        args.insert(0, &scene_path);
        if let Some(value) = &flag {
            args.push(&"--build-quality");
            args.push(value);
        }
        let output = mlt_render(&args);
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(output.status.success(), "{output:?}");
        let line = stdout
            .lines()
            .find(|l| l.contains("acceleration"))
            .unwrap_or_else(|| panic!("no acceleration row: {stdout}"));
        assert!(
            line.contains(expected) && line.contains(" s, ") && line.contains("MB"),
            "{line}"
        );
        let _ = std::fs::remove_file(&out);
    }
}

#[test]
fn the_filter_is_reported() {
    let out = temp_path("filtered.pfm");
    let output = mlt_render(&[
        &scene("cornell-glass.obj"),
        &"--algorithm",
        &"erpt",
        &"--spp",
        &"2",
        &"--filter",
        &"--filter-buffers",
        &"4",
        &"--filter-strength",
        &"0.6",
        &"--width",
        &"32",
        &"--height",
        &"32",
        &"--out",
        &out,
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{output:?}");
    let line = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("filter"))
        .unwrap_or_else(|| panic!("no filter line in:\n{stdout}"));
    assert!(
        line.contains("4 partial images, strength 0.6, radius 7"),
        "{line}"
    );
    let averaged: f64 = line
        .split(": ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no pixel count in {line}"));
    assert!(averaged > 1.0, "{line}");
}

/// A directory with a 2 × 2 quad at y = 0 facing up (diffuse, albedo 0.5) and a camera
/// looking straight down at it, filling the image: lit by nothing but what the flags add.
fn ground_scene() -> PathBuf {
    let dir = temp_path("ground");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("ground.obj"),
        "mtllib ground.mtl\nv -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nusemtl grey\nf 1 2 3 4\n",
    )
    .unwrap();
    std::fs::write(dir.join("ground.mtl"), "newmtl grey\nKd 0.5 0.5 0.5\n").unwrap();
    std::fs::write(
        dir.join("ground.camera.json"),
        r#"{"eye":[0,2,0],"target":[0,0,0],"up":[0,0,1],"fov_y_deg":40,"width":16,"height":16}"#,
    )
    .unwrap();
    dir.join("ground.obj")
}

/// Renders `obj` with path tracing and `extra` flags; the image's mean per channel and the
/// standard output.
fn render_ground(obj: &Path, extra: &[&str]) -> ([f32; 3], String) {
    let out = temp_path("ground.pfm");
    let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![
        &obj,
        &"--algorithm",
        &"path",
        &"--spp",
        &"32",
        &"--out",
        &out,
    ];
    for a in extra {
        args.push(a);
    }
    let output = mlt_render(&args);
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_summary_lines_up(&stdout);
    let (w, h, rgb) = mlt::io::read_pfm(&out).unwrap();
    std::fs::remove_file(&out).unwrap();
    let mut mean = [0.0; 3];
    for (c, m) in mean.iter_mut().enumerate() {
        *m = rgb.iter().skip(c).step_by(3).sum::<f32>() / (w * h) as f32;
    }
    (mean, stdout)
}

/// Writes a Radiance .hdr of `width` × `height` texels of radiance `rgb` with the image crate.
fn write_hdr(path: &Path, width: u32, height: u32, rgb: [f32; 3]) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let texels = vec![image::Rgb(rgb); (width * height) as usize];
    image::codecs::hdr::HdrEncoder::new(file)
        .encode(&texels, width as usize, height as usize)
        .unwrap();
}

/// The quad under a uniform sky of radiance 1 reflects 0.5 (albedo 0.5): from an .hdr file
/// (--env), as a constant (--background), scaled (--env-scale) and turned (--env-rotate,
/// which changes nothing for a uniform sky); under a delta sun straight above of
/// irradiance π it is 0.5 again (no noise but the pixel positions'), and under a sun disc
/// given by its radiance too. The checks are loose (each image is one render of 8192
/// samples); `tests/capi_images.rs` checks the same scene to its standard error.
#[test]
fn environment_and_sun_flags_light_the_scene() {
    let obj = ground_scene();
    let hdr = obj.with_file_name("sky.hdr");
    write_hdr(&hdr, 8, 4, [1.0, 1.0, 1.0]);
    let hdr_arg = hdr.to_string_lossy().into_owned();
    let close = |mean: [f32; 3], expected: f32, tolerance: f32| {
        mean.iter()
            .all(|m| (m - expected).abs() <= tolerance * expected)
    };

    let (mean, stdout) = render_ground(&obj, &["--env", &hdr_arg]);
    assert!(close(mean, 0.5, 0.05), "--env: {mean:?}");
    assert!(
        stdout.contains("lights        8 x 4 environment"),
        "{stdout}"
    );

    let (mean, stdout) = render_ground(&obj, &["--background", "1,1,1"]);
    assert!(close(mean, 0.5, 0.05), "--background: {mean:?}");
    assert!(stdout.contains("constant environment"), "{stdout}");

    let (mean, _) = render_ground(
        &obj,
        &["--env", &hdr_arg, "--env-scale", "2", "--env-rotate", "-30"],
    );
    assert!(close(mean, 1.0, 0.05), "--env-scale 2: {mean:?}");

    let pi = std::f32::consts::PI.to_string();
    let irradiance = format!("{pi},{pi},{pi}");
    let (mean, stdout) =
        render_ground(&obj, &["--sun", "0,1,0,0", "--sun-irradiance", &irradiance]);
    assert!(close(mean, 0.5, 0.01), "delta sun: {mean:?}");
    assert!(stdout.contains("sun of 0°"), "{stdout}");

    // A disc of radius 5° and radiance L straight above gives irradiance π sin²(5°) L.
    let radiance = 1.0 / 5f32.to_radians().sin().powi(2);
    let (mean, _) = render_ground(
        &obj,
        &[
            "--sun",
            "0,1,0,5",
            "--sun-radiance",
            &format!("{radiance},{radiance},{radiance}"),
        ],
    );
    assert!(close(mean, 0.5, 0.05), "sun disc: {mean:?}");
    std::fs::remove_dir_all(obj.parent().unwrap()).unwrap();
}

/// Every bad input of the command line, one row each: the arguments and what the error
/// line must name. `{cornell}`, `{glass}` and `{ground}` stand for the scene files (the Cornell
/// box, cornell-glass and `ground_scene`), `{dir}` for a folder of bad files; every row but
/// the one choosing its output writes to `--out {never}`. Each must exit with status 1 and
/// exactly one stderr line `mlt-render: ...` without a panic (`check_one_line_error`), and
/// write no image. Every row runs; the test then fails listing each failing row.
#[test]
fn bad_input_is_a_one_line_error_naming_it() {
    let ground = ground_scene();
    let dir = ground.parent().unwrap().to_path_buf();
    std::fs::write(
        dir.join("malformed.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("camera.json"),
        r#"{"eye":[278,273,-800],"target":[278,273,-799],"up":[0,1,0],"fov_y_deg":0,"width":8,"height":8}"#,
    )
    .unwrap();
    std::fs::write(dir.join("sky.png"), b"not read").unwrap();
    std::fs::write(dir.join("garbage.exr"), b"not an exr").unwrap();
    let never = temp_path("never.pfm");
    let rows: &[(&str, &[&str])] = &[
        // Files.
        ("{dir}/missing.obj", &["{dir}/missing.obj"]),
        ("{dir}/malformed.obj", &["malformed.obj", "line 5"]),
        ("{cornell} --camera {dir}/camera.json", &["fov"]),
        ("{cornell} --out x.bmp", &["x.bmp"]),
        (
            "{cornell} --variant red",
            &["only glTF files have material variants", "\"red\""],
        ),
        ("{sky} --variant red", &["no material variants", "\"red\""]),
        // A material value the kernel refuses, named with the file's material.
        (
            "{cornell} --material roughness=nan",
            &[
                "desc.materials[0].roughness is NaN; it must be a finite number",
                "(material 'white')",
            ],
        ),
        // Settings the kernel refuses (its message comes through), and clap's own errors.
        ("{cornell} --width 0", &["width"]),
        ("{cornell} --spp many", &["--spp"]),
        ("{cornell} --build-quality best", &["build-quality"]),
        (
            "{glass} --algorithm path-space-mlt --mutation-weights 0,1,1,1",
            &["bidirectional"],
        ),
        (
            "{glass} --algorithm erpt --erpt-chain-length 0",
            &["erpt_chain_length"],
        ),
        (
            "{glass} --algorithm path --filter",
            &["Metropolis and ERPT"],
        ),
        // Lights.
        ("{ground} --env {dir}/missing.hdr", &["missing.hdr"]),
        (
            "{ground} --env {dir}/sky.png",
            &["sky.png", "expected .hdr or .exr"],
        ),
        ("{ground} --env {dir}/garbage.exr", &["garbage.exr"]),
        (
            "{ground} --env {dir}/missing.hdr --background 1,1,1",
            &["--background", "--env"],
        ),
        (
            "{ground} --background -1,0,0",
            &["--background", "-1 is negative"],
        ),
        (
            "{ground} --background 1,1",
            &["--background", "3 comma-separated numbers"],
        ),
        ("{ground} --background 1,x,1", &["--background", "\"x\""]),
        (
            "{ground} --background 1,inf,1",
            &["--background", "not a finite number"],
        ),
        (
            "{ground} --env-scale -2",
            &["--env-scale", "finite number >= 0"],
        ),
        (
            "{ground} --env-rotate NaN",
            &["--env-rotate", "not a finite number"],
        ),
        (
            "{ground} --sun 0,0,0 --sun-irradiance 1,1,1",
            &["--sun", "no direction"],
        ),
        (
            "{ground} --sun 0,1",
            &["--sun", "3 or 4 comma-separated numbers"],
        ),
        (
            "{ground} --sun 0,1,0,50 --sun-irradiance 1,1,1",
            &["--sun", "[0, 45]"],
        ),
        ("{ground} --sun 0,1,0", &["--sun needs --sun-irradiance"]),
        (
            "{ground} --sun -1,1,0,0 --sun-radiance 1,1,1",
            &["--sun-radiance needs a sun of angular radius > 0"],
        ),
        ("{ground} --sun-irradiance 1,1,1", &["--sun"]),
        (
            "{ground} --sun 0,1,0 --sun-irradiance 1,-1,1",
            &["--sun-irradiance", "-1 is negative"],
        ),
    ];
    let substitute = |text: &str| {
        text.replace("{cornell}", &scene("cornell-box.obj").to_string_lossy())
            .replace("{glass}", &scene("cornell-glass.obj").to_string_lossy())
            .replace("{sky}", &scene("sky-spheres.gltf").to_string_lossy())
            .replace("{ground}", &ground.to_string_lossy())
            .replace("{dir}", &dir.to_string_lossy())
    };
    let mut failures = Vec::new();
    for (row, needles) in rows {
        // Split before substituting: a path may hold spaces.
        let mut args: Vec<String> = row.split(' ').map(substitute).collect();
        if !row.contains("--out") {
            args.extend(["--out".to_owned(), never.to_string_lossy().into_owned()]);
        }
        let args: Vec<&dyn AsRef<std::ffi::OsStr>> = args.iter().map(|a| a as _).collect();
        let needles: Vec<String> = needles.iter().map(|n| substitute(n)).collect();
        let needles: Vec<&str> = needles.iter().map(String::as_str).collect();
        if let Err(error) = check_one_line_error(&mlt_render(&args), &needles) {
            failures.push(format!("  {row}: {error}"));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} rows failed:\n{}",
        failures.len(),
        rows.len(),
        failures.join("\n")
    );
    assert!(!never.exists());
    assert!(!Path::new("x.bmp").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene without a camera (here an OBJ without its sidecar) renders through a camera
/// framing its bounds, and the camera is printed as sidecar JSON that loads back.
#[test]
fn a_scene_without_a_camera_is_framed_and_the_camera_printed() {
    let dir = temp_path("framed");
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("quad.obj");
    std::fs::write(
        &obj,
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let out = dir.join("quad.pfm");
    let output = mlt_render(&[
        &obj,
        &"--algorithm",
        &"path",
        &"--spp",
        &"1",
        &"--width",
        &"8",
        &"--height",
        &"8",
        &"--background",
        &"1,1,1",
        &"--out",
        &out,
    ]);
    assert!(output.status.success(), "{output:?}");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("has no camera"), "{stderr}");
    let json = &stderr[stderr.find('{').expect("the camera's JSON")..];
    let sidecar = dir.join("framed.camera.json");
    std::fs::write(&sidecar, &json[..=json.rfind('}').unwrap()]).unwrap();
    let camera = mlt::io::load_camera_json(&sidecar).unwrap();
    // Looking at the quad's centre from the front (+z), far enough to see all of it.
    assert_eq!(camera.camera.target, [0.0; 3]);
    assert!(camera.camera.eye[2] > 2.0, "{:?}", camera.camera.eye);
    assert!(out.is_file());
}

/// Every declared render setting has its flag, with the declared default (the image size's
/// is the camera's), and a value outside its range is refused with the message every front
/// end gives.
#[test]
fn every_setting_has_its_flag_default_and_message() {
    use mlt::RenderSettings;
    use mlt::params::{Kind, Parameters, Value};
    let help = String::from_utf8(mlt_render(&[&"--help"]).stdout).unwrap();
    let text = |kind: Kind, value: Value| match (kind, value) {
        (Kind::F32, Value::Float(v)) => (v as f32).to_string(),
        (_, Value::Floats(v)) => v.map(|x| x.to_string()).join(","),
        (_, v) => v.to_string(),
    };
    for p in RenderSettings::parameters() {
        let flag = format!("--{}", p.flag.unwrap());
        // The flag's entry: its line and the indented help lines below it.
        let lines: Vec<&str> = help.lines().collect();
        let first = lines
            .iter()
            .position(|l| {
                let l = l.trim_start();
                l.strip_prefix(&flag)
                    .is_some_and(|rest| rest.is_empty() || rest.starts_with([' ', ',']))
            })
            .unwrap_or_else(|| panic!("no {flag} in:\n{help}"));
        let last = lines[first + 1..]
            .iter()
            .position(|l| l.trim_start().starts_with('-') || l.is_empty())
            .map_or(lines.len(), |n| first + 1 + n);
        let entry = lines[first..last].join(" ");
        assert!(entry.contains(p.doc.trim_end_matches('.')), "{entry}");
        if !matches!(p.kind, Kind::Bool) && !["width", "height"].contains(&p.name) {
            let default = format!("[default: {}]", text(p.kind, (p.default)()));
            assert!(entry.contains(&default), "{default} not in {entry}");
        }
        let Some(bad) = p.outside_value() else {
            continue;
        };
        let mut settings = RenderSettings::default();
        settings.set(p.name, bad).unwrap();
        let expected = settings.validate().unwrap_err().message;
        let out = temp_path("never-written.pfm");
        let value = text(p.kind, bad);
        // The declared image size, so that settings ruled by it (the chains, by the
        // bootstrap) are refused as from the other front ends.
        let mut args: Vec<std::ffi::OsString> = vec![
            scene("cornell-box.obj").into(),
            flag.into(),
            value.clone().into(),
        ];
        for size in ["width", "height"] {
            if p.name != size {
                args.extend([format!("--{size}").into(), "256".into()]);
            }
        }
        args.extend(["--out".into(), out.into()]);
        let args: Vec<&dyn AsRef<std::ffi::OsStr>> = args.iter().map(|a| a as _).collect();
        let output = mlt_render(&args);
        let line = assert_one_line_error(&output);
        assert!(
            line.contains(&expected),
            "--{} {value}: {line}, not {expected}",
            p.flag.unwrap()
        );
    }
}

/// Every declared material parameter can be set with `--material NAME=VALUE`, its default
/// is in the long help, and a value outside its range is refused with the message every
/// front end gives.
#[test]
fn every_material_parameter_is_an_override_with_its_default_and_message() {
    use mlt::Material;
    use mlt::params::{Kind, Parameters, Value};
    let help = String::from_utf8(mlt_render(&[&"--help"]).stdout).unwrap();
    let text = |kind: Kind, value: Value| match (kind, value) {
        (Kind::F32, Value::Float(v)) => (v as f32).to_string(),
        (_, v) => v.to_string(),
    };
    for p in Material::parameters() {
        let entry = format!(
            "{}  {} [default: {}]",
            p.name,
            p.doc,
            text(p.kind, (p.default)())
        );
        assert!(help.contains(&entry), "no {entry:?} in:\n{help}");
        let Some(bad) = p.outside_value() else {
            continue;
        };
        let mut material = Material::default();
        material.set(p.name, bad).unwrap();
        let expected = material.validate(0, 0).unwrap_err().message;
        let out = temp_path("never-written.pfm");
        let setting = format!("{}={}", p.name, text(p.kind, bad));
        let output = mlt_render(&[
            &scene("cornell-box.obj"),
            &"--material",
            &setting,
            &"--out",
            &out,
        ]);
        let line = assert_one_line_error(&output);
        assert!(
            line.contains(&expected),
            "--material {setting}: {line}, not {expected}"
        );
    }
    // A name that is not a parameter, and a value of another kind, are refused by name.
    for (setting, message) in [
        (
            "sheen=1",
            "\"sheen\" is not a material parameter; they are kind, color",
        ),
        ("kind=velvet", "\"velvet\": expected one of diffuse, mirror"),
        ("color=1,1", "3 numbers are needed, not 2"),
        ("normal_texture=-2", "expected none or a texture's index"),
    ] {
        let output = mlt_render(&[
            &scene("cornell-box.obj"),
            &"--material",
            &setting,
            &"--out",
            &temp_path("never-written.pfm"),
        ]);
        let line = assert_one_line_error(&output);
        assert!(line.contains(message), "--material {setting}: {line}");
    }
}

/// `--material` overrides what the file says: a clay render of the Cornell box is grey
/// where the file's walls are red and green.
#[test]
fn material_overrides_make_a_clay_render() {
    let out = temp_path("clay.pfm");
    let output = mlt_render(&[
        &scene("cornell-box.obj"),
        &"--algorithm",
        &"path",
        &"--spp",
        &"4",
        &"--width",
        &"16",
        &"--height",
        &"16",
        &"--material",
        &"kind=diffuse",
        &"--material",
        &"color=0.5,0.5,0.5",
        &"--out",
        &out,
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let (_, _, pixels) = mlt::io::read_pfm(&out).unwrap();
    // Grey walls: every pixel has the light's colour (Ke 17 12 4), whose ratios the file's
    // red and green walls would change.
    assert!(pixels.iter().any(|&v| v > 0.0));
    for px in pixels.chunks_exact(3) {
        let [r, g, b] = [px[0] / 17.0, px[1] / 12.0, px[2] / 4.0];
        assert!(
            (r - g).abs() <= 1e-5 * r && (g - b).abs() <= 1e-5 * g,
            "{px:?}"
        );
    }
}

/// A material the kernel refuses is named as the file names it: the kernel's error says
/// which material it is about, not only by its text.
#[test]
fn a_refused_material_is_named_from_the_file() {
    let dir = temp_path("bad-material");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("bad.mtl"),
        "newmtl fine\nKd 0.5 0.5 0.5\nnewmtl too_bright\nKd 1.5 0.5 0.5\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("bad.obj"),
        "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl fine\nf 1 2 3\nusemtl too_bright\nf 1 3 2\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("bad.camera.json"),
        r#"{"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40, "width": 4, "height": 4}"#,
    )
    .unwrap();
    let output = mlt_render(&[&dir.join("bad.obj"), &"--out", &dir.join("out.pfm")]);
    let line = assert_one_line_error(&output);
    assert!(
        line.contains("desc.materials[1].color.x is 1.5")
            && line.ends_with("(material 'too_bright')"),
        "{line}"
    );
}
