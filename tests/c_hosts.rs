//! Compiles the C and C++ examples in c_examples/ against include/mlt.h (and the C++ ones
//! against include/mlt.hpp, as C++17 and C++20) and the static library cargo built, runs
//! them on a small image and checks their PFM output against the same render through the
//! Rust API (rendering is deterministic given the seed, so they must agree bit for bit).
//! The README's C and C++ examples are built and run too.
//!
//! Finding the library: `cargo test` builds the `mlt` lib target once with all its crate types
//! (rlib, staticlib, cdylib), so `libmlt.a` sits next to this test's executable in
//! `target/<profile>/deps/`, from the very compilation that is linked into this test. After a
//! plain `cargo build` it is in `target/<profile>/`. If neither exists (an unusual runner), the
//! test runs `cargo build --lib` and takes the path cargo reports.
//!
//! The module `install` (c_hosts/install.rs) installs the same library with CMake and builds
//! hosts against the installed prefix through pkg-config and `find_package`.
//!
//! Runs in about 52 s on 2 cores (`cargo test --test c_hosts`).

// The shared helpers by path: with a directory tests/c_hosts/ beside this file, rustfmt
// would look for an inline `mod common`'s files there.
#[path = "common/compiler.rs"]
mod compiler;
#[path = "c_hosts/install.rs"]
mod install;
#[path = "common/scenes.rs"]
mod scenes;
#[path = "common/stats.rs"]
mod stats;

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

const WIDTH: u32 = 64;
const HEIGHT: u32 = 64;
/// Mutations per pixel of the default algorithm (Metropolis), the examples' fourth argument.
const MUTATIONS: u32 = 4;

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The static library, located once per test process.
fn static_lib() -> &'static Path {
    static LIB: OnceLock<PathBuf> = OnceLock::new();
    LIB.get_or_init(|| {
        let exe = std::env::current_exe().expect("the test executable's path");
        let deps = exe.parent().expect("target/<profile>/deps");
        let candidates = [
            deps.join("libmlt.a"),
            deps.parent()
                .map(|p| p.join("libmlt.a"))
                .unwrap_or_default(),
        ];
        for candidate in candidates {
            if candidate.is_file() {
                return candidate;
            }
        }
        build_static_lib()
    })
}

/// Fallback: asks cargo to build the library and report where the staticlib went.
fn build_static_lib() -> PathBuf {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let output = Command::new(cargo)
        .args(["build", "--lib", "--message-format=json"])
        .current_dir(crate_dir())
        .output()
        .expect("running cargo build --lib");
    assert!(
        output.status.success(),
        "cargo build --lib failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    for line in stdout.lines() {
        // Each artifact line lists "filenames":[...]; pick the one ending in libmlt.a.
        if !line.contains("\"compiler-artifact\"") {
            continue;
        }
        for piece in line.split('"') {
            if piece.ends_with("/libmlt.a") || piece.ends_with("\\libmlt.a") {
                return PathBuf::from(piece);
            }
        }
    }
    panic!("cargo build --lib did not report a libmlt.a; output:\n{stdout}");
}

fn scratch_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .unwrap_or(Path::new("."))
        .join("c_hosts");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Compiles `source` (C unless `as_cpp`, with `std`) against include/mlt.h, links the
/// static library, and returns the executable.
fn build(source: &str, exe_name: &str, as_cpp: bool, extra: &[&str]) -> PathBuf {
    build_with_header(
        &crate_dir().join("include"),
        source,
        exe_name,
        as_cpp,
        extra,
    )
}

/// [`build`] against the mlt.h in `include_dir`.
fn build_with_header(
    include_dir: &Path,
    source: &str,
    exe_name: &str,
    as_cpp: bool,
    extra: &[&str],
) -> PathBuf {
    let mut flags: Vec<OsString> = vec!["-I".into(), include_dir.into()];
    flags.extend(extra.iter().map(OsString::from));
    let mut libs: Vec<OsString> = vec![static_lib().into()];
    if cfg!(feature = "embree") {
        // The static library's own native dependency in this build.
        libs.push("-lembree3".into());
    }
    libs.extend(["-lpthread", "-ldl", "-lm"].map(OsString::from));
    if cfg!(target_os = "macos") {
        libs.extend(["-framework", "Security", "-framework", "CoreFoundation"].map(OsString::from));
    }
    compile(source, exe_name, as_cpp, &flags, &libs)
}

/// Compiles `c_examples/<source>` (C unless `as_cpp`) with the warnings as errors and
/// `flags`, links it with `libs` and returns the executable.
fn compile(
    source: &str,
    exe_name: &str,
    as_cpp: bool,
    flags: &[OsString],
    libs: &[OsString],
) -> PathBuf {
    let out = scratch_dir().join(exe_name);
    let _ = std::fs::remove_file(&out);
    let mut cmd = compiler::compiler(as_cpp);
    cmd.args(["-Wall", "-Wextra", "-Werror", "-pedantic"])
        .args(flags)
        .arg(crate_dir().join("c_examples").join(source))
        // Whatever follows is a library, not source in the language given by `-x`.
        .arg("-x")
        .arg("none")
        .args(libs)
        .arg("-o")
        .arg(&out);
    let output = cmd
        .output()
        .unwrap_or_else(|e| panic!("could not run the compiler {cmd:?}: {e}"));
    assert!(
        output.status.success(),
        "compiling {source} failed: {cmd:?}\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    // Warnings are errors, but make sure nothing slipped through on stderr either.
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !stderr.contains("warning"),
        "{source} compiled with warnings:\n{stderr}"
    );
    out
}

struct Pfm {
    width: usize,
    height: usize,
    /// RGB rows from the TOP of the image down (flipped from the file's bottom-up order).
    rgb: Vec<f32>,
}

fn read_pfm(path: &Path) -> Pfm {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("reading {path:?}: {e}"));
    // Three whitespace-terminated header tokens: "PF", "<w> <h>", "-1.0".
    let mut tokens = Vec::new();
    let mut at = 0;
    while tokens.len() < 4 {
        while bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        tokens.push(std::str::from_utf8(&bytes[start..at]).unwrap().to_string());
    }
    assert_eq!(bytes[at], b'\n', "a single newline ends the PFM header");
    at += 1;
    assert_eq!(tokens[0], "PF", "an RGB PFM");
    let width: usize = tokens[1].parse().unwrap();
    let height: usize = tokens[2].parse().unwrap();
    let scale: f32 = tokens[3].parse().unwrap();
    assert!(scale < 0.0, "little-endian PFM (negative scale)");
    let data = &bytes[at..];
    assert_eq!(data.len(), width * height * 3 * 4, "PFM payload size");
    let floats: Vec<f32> = data
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let mut rgb = Vec::with_capacity(floats.len());
    for row in floats.chunks_exact(width * 3).rev() {
        rgb.extend_from_slice(row);
    }
    Pfm { width, height, rgb }
}

/// The same render through the Rust API, from the canonical OBJ file.
fn reference() -> &'static [f32] {
    static IMAGE: OnceLock<Vec<f32>> = OnceLock::new();
    IMAGE.get_or_init(|| {
        let scene = scenes::cornell_box().scene();
        let settings = mlt::RenderSettings {
            width: WIDTH,
            height: HEIGHT,
            mutations_per_pixel: MUTATIONS,
            ..Default::default()
        };
        let mut image = vec![0.0f32; (WIDTH * HEIGHT * 3) as usize];
        let stats = mlt::render(
            &scene,
            &scenes::cornell_camera(),
            &settings,
            &mut image,
            None,
        )
        .unwrap();
        assert_eq!(stats.stop, mlt::StopReason::Completed);
        image
    })
}

fn run_and_check(exe: &Path, name: &str) -> String {
    let pfm_path = scratch_dir().join(format!("{name}.pfm"));
    let _ = std::fs::remove_file(&pfm_path);
    let output = Command::new(exe)
        .arg(&pfm_path)
        .args([WIDTH, HEIGHT, MUTATIONS].map(|v| v.to_string()))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout).to_string();
    assert!(
        output.status.success(),
        "{name} failed ({}):\n{stdout}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let image = read_pfm(&pfm_path);
    assert_eq!(
        (image.width, image.height),
        (WIDTH as usize, HEIGHT as usize)
    );
    assert!(image.rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    check_picture(&image, name);

    let expected = reference();
    let mut mismatches = 0;
    for (i, (a, b)) in image.rgb.iter().zip(expected).enumerate() {
        if a.to_bits() != b.to_bits() {
            if mismatches < 5 {
                eprintln!("{name}: float {i} is {a}, the Rust API gives {b}");
            }
            mismatches += 1;
        }
    }
    assert_eq!(
        mismatches, 0,
        "{name}'s image differs from the Rust API's render"
    );
    stdout
}

/// Plausibility checks that catch flipped or mirrored images and broken lighting.
fn check_picture(image: &Pfm, name: &str) {
    let (w, h) = (image.width, image.height);
    let pixel = |x: usize, y: usize| &image.rgb[(y * w + x) * 3..(y * w + x) * 3 + 3];
    let mean = stats::mean(&image.rgb);
    // The Cornell box at the light's (17, 12, 4): the mean is roughly (0.19, 0.12, 0.036).
    assert!(
        (0.05..2.0).contains(&mean[0]) && mean[0] > mean[2],
        "{name}: implausible mean {mean:?}"
    );
    // The light (radiance 17, 12, 4 seen directly) is in the top rows, not the bottom ones.
    let light_rows: Vec<usize> = (0..h)
        .filter(|&y| (0..w).any(|x| pixel(x, y)[0] > 10.0))
        .collect();
    assert!(!light_rows.is_empty(), "{name}: the light is not visible");
    assert!(
        light_rows.iter().all(|&y| y < h / 4),
        "{name}: the light should be near the top, found in rows {light_rows:?} (image upside down?)"
    );
    // The red wall is on the left, the green one on the right.
    let column_mean = |x0: usize, x1: usize| {
        let mut s = [0.0f64; 3];
        for y in 0..h {
            for x in x0..x1 {
                for (sum, &value) in s.iter_mut().zip(pixel(x, y)) {
                    *sum += value as f64;
                }
            }
        }
        s
    };
    let left = column_mean(0, w / 10);
    let right = column_mean(w - w / 10, w);
    assert!(left[0] > left[1], "{name}: the left wall is not red");
    assert!(right[1] > right[0], "{name}: the right wall is not green");
}

#[test]
fn minimal_c_compiles_as_c99_and_matches_the_rust_api() {
    let exe = build("minimal.c", "minimal_c99", false, &["-std=c99"]);
    let stdout = run_and_check(&exe, "minimal_c99");
    assert!(stdout.contains("32 triangles"), "{stdout}");
}

/// A host compiled against an older header (tests/previous_header/mlt.h: the settings and
/// stats before the post-process filter's fields) passes smaller structs; mlt reads what
/// they have and defaults the rest, so the image is the current API's, bit for bit.
#[test]
fn a_host_built_against_the_previous_header_renders() {
    let previous = crate_dir().join("tests").join("previous_header");
    let header = std::fs::read_to_string(previous.join("mlt.h")).unwrap();
    assert!(
        !header.contains("filter_buffers;") && header.contains("struct_size;"),
        "the previous header lacks the filter fields and has struct_size"
    );
    let exe = build_with_header(
        &previous,
        "minimal.c",
        "minimal_previous_header",
        false,
        &["-std=c99"],
    );
    let stdout = run_and_check(&exe, "minimal_previous_header");
    assert!(stdout.contains("32 triangles"), "{stdout}");
}

#[test]
fn minimal_c_compiles_as_cpp_and_matches_the_rust_api() {
    let exe = build("minimal.c", "minimal_cpp", true, &["-x", "c++"]);
    run_and_check(&exe, "minimal_cpp");
}

/// The C++ standards `include/mlt.hpp` supports, each checked with the warnings as errors.
const CPP_STANDARDS: [&str; 2] = ["c++17", "c++20"];

/// `c_examples/cornell.cpp` uses `include/mlt.hpp` (RAII scene, exceptions, spans, a progress
/// lambda); as C++17 and C++20 it renders the Rust API's image and answers ray queries.
#[test]
fn cornell_cpp_renders_and_answers_ray_queries() {
    for std in CPP_STANDARDS {
        let name = format!("cornell_{}", std.replace('+', "p"));
        let exe = build("cornell.cpp", &name, true, &[&format!("-std={std}")]);
        let stdout = run_and_check(&exe, &name);
        assert!(stdout.contains("scene: 32 triangles, 2 lights"), "{stdout}");
        assert!(stdout.contains("ray 0 hits the back wall"), "{stdout}");
        assert!(stdout.contains("ray 1: miss"), "{stdout}");
        assert!(
            stdout.contains("floor point 0 is lit, floor point 1 is in shadow"),
            "{stdout}"
        );
    }
}

/// Every declared render setting reaches C (`MltRenderSettings`) and C++
/// (`mlt::RenderSettings`), and every material parameter `MltMaterial` and `mlt::Material`,
/// with its declared default, and a value outside its range, set in either, is refused with
/// the message Rust's validation gives (`c_examples/parameters.cpp`, generated from the
/// declarations by `tests/parameters.rs`).
#[test]
fn every_parameter_reaches_c_and_cpp_with_its_default_and_message() {
    let exe = build("parameters.cpp", "parameters", true, &["-std=c++17"]);
    let output = Command::new(&exe).output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    check_parameters::<mlt::RenderSettings>(&stdout, "", |s| s.validate());
    // The program's material is the scene's only one.
    check_parameters::<mlt::Material>(&stdout, "material.", |m| m.validate(0, 0));
}

/// The lines of `parameters.cpp` about `S`'s parameters (named `label` + name) against the
/// declarations; `validate` gives the message of an out-of-range value.
fn check_parameters<S: mlt::params::Parameters>(
    stdout: &str,
    label: &str,
    validate: fn(&S) -> mlt::Result<()>,
) {
    use mlt::params::{Kind, Value};
    // A printed value ("%.9g" for floats, "%.17g" for doubles, 0 or 1 for booleans, the
    // MLT_* code of a choice, a texture slot's index) and the declared one are the same.
    let same = |kind: Kind, text: &str, value: Value| -> bool {
        let words: Vec<&str> = text.split(' ').collect();
        let floats = |v: &[f32]| {
            words
                .iter()
                .map(|w| w.parse::<f32>().ok())
                .eq(v.iter().map(|&x| Some(x)))
        };
        match (kind, value) {
            (_, Value::Int(v)) => words == [v.to_string()],
            (Kind::F32, Value::Float(v)) => words[0].parse::<f32>() == Ok(v as f32),
            (_, Value::Float(v)) => words[0].parse::<f64>() == Ok(v),
            (_, Value::Bool(v)) => words == [(v as u32).to_string()],
            (Kind::Choice(choices), Value::Choice(name)) => {
                words
                    == [choices
                        .names
                        .iter()
                        .position(|&n| n == name)
                        .unwrap()
                        .to_string()]
            }
            (_, Value::Vec3(v)) => floats(&v),
            (_, Value::Floats(v)) => floats(&v),
            (_, Value::Texture(None)) => words == ["-1"],
            (_, Value::Texture(Some(t))) => words == [t.texture.to_string()],
            (_, Value::Choice(_)) => false,
        }
    };
    for p in S::parameters() {
        let name = format!("{label}{}", p.name);
        for language in ["c", "c++"] {
            let prefix = format!("{language} {name} ");
            let shown = stdout
                .lines()
                .find_map(|l| {
                    l.strip_prefix(&prefix)
                        .filter(|v| !v.starts_with("message"))
                })
                .unwrap_or_else(|| panic!("no default of {name} in {language}:\n{stdout}"));
            assert!(
                same(p.kind, shown, (p.default)()),
                "{language}'s default of {name} is {shown}, declared {:?}",
                (p.default)()
            );
            let Some(bad) = p.outside_value() else {
                continue;
            };
            let mut value = S::default();
            value.set(p.name, bad).unwrap();
            let expected = validate(&value).unwrap_err().message;
            let line = format!("{language} {name} message {expected}");
            assert!(
                stdout.lines().any(|l| l == line),
                "no {line:?} in:\n{stdout}"
            );
        }
    }
}

/// `c_examples/cpp_checks.cpp` checks what `include/mlt.hpp` adds to the C API: defaults
/// equal to the library's, errors as `mlt::Error` with the status and message, progress
/// lambdas that cancel or throw (the render is cancelled and the exception reaches the
/// caller), spans (and `std::span` in C++20), the scene handle's ownership, and split
/// renders (`mlt::render_plan`, `render_job`, `render_merge`, `mlt::Bytes`).
#[test]
fn cpp_header_reports_errors_and_cancels_from_callbacks() {
    for std in CPP_STANDARDS {
        let name = format!("cpp_checks_{}", std.replace('+', "p"));
        let exe = build("cpp_checks.cpp", &name, true, &[&format!("-std={std}")]);
        let output = Command::new(&exe).output().unwrap();
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(
            output.status.success(),
            "{name} failed ({}):\n{stdout}\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        );
        let version = std.trim_start_matches("c++");
        for line in [
            "ok: mlt::RenderSettings{} is mlt_render_settings_default",
            "ok: a bad setting throws mlt::Error: mlt_render: invalid argument: settings.width is 0",
            "ok: a lambda returning false cancels the render",
            "ok: TextureRef::texcoord 1 reads SceneDesc::texcoords1; texcoord1_slots round-trips; set 1 without texcoords1, and set 2, throw",
            "ok: a lambda's exception cancels the render and is rethrown after it",
            "ok: an exception from the final progress call is rethrown",
            "ok: mlt::Scene moves, copies (sharing), releases and adopts its handle; ray queries answer",
            "ok: mlt::render_plan, render_job, render_combine and render_merge: 3 jobs merge into render's image",
            "ok: split renders throw on bad input; a cancelled job gives its partial result; mlt::Bytes owns its bytes",
            &format!("all checks passed (C++{version})"),
        ] {
            assert!(stdout.contains(line), "{name}: no {line:?} in\n{stdout}");
        }
        let spans = if version == "20" {
            "ok: C++20: render into a std::span, and mlt::Span converts to std::span"
        } else {
            "ok: C++17: mlt::Span without std::span"
        };
        assert!(stdout.contains(spans), "{name}: no {spans:?} in\n{stdout}");
    }
}

/// `include/mlt.hpp` is written by hand, so a field added to one of the C structs it
/// mirrors must be added to it too: every field of those structs in the generated mlt.h
/// (but `struct_size`, which the initializers set) is read or written as `c.<field>` in
/// mlt.hpp's conversions.
#[test]
fn cpp_header_mirrors_every_field_of_the_c_structs() {
    let header = std::fs::read_to_string(crate_dir().join("include").join("mlt.h")).unwrap();
    let cpp = std::fs::read_to_string(crate_dir().join("include").join("mlt.hpp")).unwrap();
    let mut checked = 0;
    for name in [
        "MltTextureRef",
        "MltMaterial",
        "MltTexture",
        "MltEnvironment",
        "MltSun",
        "MltPunctualLight",
        "MltSceneDesc",
        "MltCamera",
        "MltRenderSettings",
        "MltRenderStats",
        "MltSceneInfo",
    ] {
        let start = header
            .find(&format!("typedef struct {name} {{"))
            .unwrap_or_else(|| panic!("mlt.h defines {name}"));
        let end = start
            + header[start..]
                .find(&format!("}} {name};"))
                .unwrap_or_else(|| panic!("the end of {name}"));
        let fields: Vec<&str> = header[start..end]
            .lines()
            .skip(1)
            .map(str::trim)
            .filter(|line| line.ends_with(';') && !line.starts_with('*') && !line.starts_with('/'))
            .map(|line| {
                let declaration = line.trim_end_matches(';');
                let declarator = declaration.split('[').next().unwrap();
                declarator
                    .rsplit(|c: char| c.is_whitespace() || c == '*')
                    .next()
                    .unwrap()
            })
            // `_reserved` only keeps a layout's size apart: nothing to convert.
            .filter(|&field| field != "struct_size" && field != "_reserved")
            .collect();
        assert!(!fields.is_empty(), "no fields found in {name}");
        for field in fields {
            assert!(
                [" ", ",", ")", ";"]
                    .iter()
                    .any(|end| cpp.contains(&format!("c.{field}{end}"))),
                "include/mlt.hpp does not convert {name}.{field}: add it to the C++ struct and \
                 its to_c / from_c"
            );
            checked += 1;
        }
    }
    assert!(checked > 100, "only {checked} fields found");
}

#[test]
fn minimal_c_reports_a_bad_size_through_the_status_helper() {
    let exe = build("minimal.c", "minimal_bad_size", false, &["-std=c99"]);
    let pfm = scratch_dir().join("minimal_bad_size.pfm");
    let output = Command::new(exe)
        .arg(&pfm)
        .args(["0", "64", "8"])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("mlt_render failed: invalid argument") && stderr.contains("width is 0"),
        "{stderr}"
    );
}

/// `c_examples/sky.c` lights a ground square only by a constant environment set through
/// `mlt_environment_constant`: every pixel converges to 0.5 (albedo 0.5 under radiance 1),
/// checked against the standard error of the pixels' mean. Built as C99 and as C++.
#[test]
fn sky_c_lights_a_scene_with_a_constant_environment() {
    for (exe_name, as_cpp, flags) in [
        ("sky_c99", false, &["-std=c99"][..]),
        ("sky_cpp", true, &["-x", "c++"][..]),
    ] {
        let exe = build("sky.c", exe_name, as_cpp, flags);
        let pfm_path = scratch_dir().join(format!("{exe_name}.pfm"));
        let _ = std::fs::remove_file(&pfm_path);
        let output = Command::new(exe)
            .arg(&pfm_path)
            .args(["16", "16", "64"])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(
            output.status.success(),
            "{exe_name}: {stdout}{}",
            String::from_utf8_lossy(&output.stderr)
        );
        assert!(stdout.contains("(converges to 0.5)"), "{stdout}");
        let image = read_pfm(&pfm_path);
        assert_eq!((image.width, image.height), (16, 16));
        let (mean, error) = stats::mean_and_standard_error(&image.rgb);
        for c in 0..3 {
            stats::assert_within_and_sharp(
                &format!("{exe_name} channel {c}"),
                mean[c],
                0.5,
                error[c],
                4.0,
            );
        }
    }
}

/// `c_examples/textured.c` renders a square with a 2 × 2 checker base colour texture (8-bit
/// sRGB, nearest texel), per-vertex normals and texture coordinates under a white sky,
/// with a metallic-roughness material. The checker must appear upright: uv
/// (0, 0) is the texture's top-left texel, whose dark value lands in the image's top-left
/// quarter. With set 1 the texture reads the second set of texture coordinates (u
/// mirrored, `MLT_TEXCOORD1_BASE_COLOR`), and the checker must appear mirrored. Built as
/// C99 and as C++.
#[test]
fn textured_c_renders_a_checker_with_normals_and_texture_coordinates() {
    for (exe_name, as_cpp, flags) in [
        ("textured_c99", false, &["-std=c99"][..]),
        ("textured_cpp", true, &["-x", "c++"][..]),
    ] {
        let exe = build("textured.c", exe_name, as_cpp, flags);
        for set in ["0", "1"] {
            let pfm_path = scratch_dir().join(format!("{exe_name}_set{set}.pfm"));
            let _ = std::fs::remove_file(&pfm_path);
            let output = Command::new(&exe)
                .arg(&pfm_path)
                .args(["32", "32", "16", set])
                .output()
                .unwrap();
            let stdout = String::from_utf8_lossy(&output.stdout);
            assert!(
                output.status.success(),
                "{exe_name} set {set}: {stdout}{}",
                String::from_utf8_lossy(&output.stderr)
            );
            let image = read_pfm(&pfm_path);
            assert_eq!((image.width, image.height), (32, 32));
            assert!(image.rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
            // Each quarter's mean, 2 pixels away from the checker's edges.
            let quarter = |x0: usize, y0: usize| {
                let mut sum = 0.0f64;
                let mut n = 0;
                for y in y0 + 2..y0 + 14 {
                    for x in x0 + 2..x0 + 14 {
                        let i = (y * 32 + x) * 3;
                        sum += image.rgb[i..i + 3].iter().map(|&v| v as f64).sum::<f64>() / 3.0;
                        n += 1;
                    }
                }
                sum / n as f64
            };
            let diagonal = [
                ("top-left", quarter(0, 0)),
                ("bottom-right", quarter(16, 16)),
            ];
            let antidiagonal = [
                ("top-right", quarter(16, 0)),
                ("bottom-left", quarter(0, 16)),
            ];
            // Set 0 is upright, set 1 mirrored.
            let (dark, white) = match set {
                "0" => (diagonal, antidiagonal),
                _ => (antidiagonal, diagonal),
            };
            for (name, value) in dark {
                assert!(
                    value < 0.2,
                    "{exe_name} set {set}: the {name} quarter is {value}, not dark (sRGB 64 is 0.05)\n{stdout}"
                );
            }
            for (name, value) in white {
                assert!(
                    (0.6..1.3).contains(&value),
                    "{exe_name} set {set}: the {name} quarter is {value}, not white\n{stdout}"
                );
            }
        }
    }
}

/// `c_examples/split_render.c` plans a render, renders it as 3 jobs whose partial results
/// go through temporary files, combines two and merges them in another order, checks the image against
/// `mlt_render` bit for bit and that a corrupted partial result is refused. Its image must
/// also be the Rust API's render, bit for bit. Built as C99 and as C++, with the path tracer
/// and BDPT.
#[test]
fn split_render_c_merges_three_jobs_into_the_bits_of_one_render() {
    let scene = scenes::cornell_box().scene();
    for (exe_name, as_cpp, flags) in [
        ("split_render_c99", false, &["-std=c99"][..]),
        ("split_render_cpp", true, &["-x", "c++"][..]),
    ] {
        let exe = build("split_render.c", exe_name, as_cpp, flags);
        for (algorithm, name) in [
            (mlt::Algorithm::Path, "path"),
            (mlt::Algorithm::Bdpt, "bdpt"),
        ] {
            let pfm_path = scratch_dir().join(format!("{exe_name}_{name}.pfm"));
            let _ = std::fs::remove_file(&pfm_path);
            let output = Command::new(&exe)
                .arg(&pfm_path)
                .args(["32", "24", "4", name])
                .output()
                .unwrap();
            let stdout = String::from_utf8_lossy(&output.stdout);
            assert!(
                output.status.success(),
                "{exe_name} {name} failed ({}):\n{stdout}{}",
                output.status,
                String::from_utf8_lossy(&output.stderr)
            );
            for line in [
                "job 2 of 3:",
                "combined 2 partial results:",
                "merged 3 jobs:",
                "a corrupted partial result is refused: partials[1]: the partial render's checksum does not match",
                "the merged image equals mlt_render's bit for bit",
            ] {
                assert!(
                    stdout.contains(line),
                    "{exe_name} {name}: no {line:?} in\n{stdout}"
                );
            }
            let settings = mlt::RenderSettings {
                width: 32,
                height: 24,
                algorithm,
                samples_per_pixel: 4,
                seed: 7,
                ..Default::default()
            };
            let mut expected = vec![0.0f32; settings.output_len().unwrap()];
            mlt::render(
                &scene,
                &scenes::cornell_camera(),
                &settings,
                &mut expected,
                None,
            )
            .unwrap();
            let image = read_pfm(&pfm_path);
            assert_eq!((image.width, image.height), (32, 24));
            assert!(
                image
                    .rgb
                    .iter()
                    .zip(&expected)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{exe_name} {name}: the merged image differs from the Rust API's render"
            );
        }
    }
}

/// A host program of c_examples/ and how a memory check runs it.
struct HostRun {
    source: &'static str,
    /// The language standard (C unless it starts with "c++").
    std: &'static str,
    args: &'static [&'static str],
}

impl HostRun {
    fn build(&self, tag: &str, flags: &[&str]) -> PathBuf {
        let as_cpp = self.std.starts_with("c++");
        let name = format!("{}_{tag}", self.source.replace('.', "_"));
        let std = format!("-std={}", self.std);
        let mut all = vec![std.as_str()];
        all.extend_from_slice(flags);
        build(self.source, &name, as_cpp, &all)
    }

    /// The arguments, "OUT" replaced by an output file of its own for `tag`.
    fn args(&self, tag: &str) -> Vec<String> {
        let out = scratch_dir().join(format!("{}_{tag}.pfm", self.source));
        self.args
            .iter()
            .map(|&a| match a {
                "OUT" => out.to_string_lossy().into_owned(),
                _ => a.to_string(),
            })
            .collect()
    }
}

/// The stress program (c_examples/stress.c): many random scenes with cancels and time
/// limits, renders and queries from several host threads, a scene released under running
/// renders, and every kind of bad input.
const STRESS: HostRun = HostRun {
    source: "stress.c",
    std: "c11",
    args: &["1", "24"],
};

/// What runs under both the sanitizers and memcheck, sized for memcheck (about 50 times
/// slower). minimal.c and cornell.cpp use the default 2^18 bootstrap samples, too many for
/// memcheck; the stress program covers what they call.
const CHECKED_HOSTS: [HostRun; 5] = [
    HostRun {
        source: "sky.c",
        std: "c99",
        args: &["OUT", "16", "16", "2"],
    },
    HostRun {
        source: "textured.c",
        std: "c99",
        args: &["OUT", "16", "16", "2"],
    },
    HostRun {
        source: "cpp_checks.cpp",
        std: "c++17",
        args: &[],
    },
    HostRun {
        args: &["4", "12"],
        ..STRESS
    },
    HostRun {
        source: "split_render.c",
        std: "c99",
        args: &["OUT", "16", "16", "2"],
    },
];

#[test]
fn stress_program_passes_its_checks() {
    let exe = STRESS.build("plain", &["-O2"]);
    for seed in ["2", "3"] {
        let output = Command::new(&exe).args([seed, "24"]).output().unwrap();
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(
            output.status.success() && stdout.contains("all checks passed"),
            "stress {seed} failed ({}):\n{stdout}\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        );
    }
}

/// Every C and C++ host, built with AddressSanitizer and UndefinedBehaviorSanitizer (leak
/// checking included), runs clean. The sanitizers instrument the hosts' code and watch
/// every allocation and free, mlt's included (mlt's Rust code is not instrumented: valgrind
/// below checks its memory accesses). minimal.c and cornell.cpp must still give the Rust
/// API's image bit for bit.
#[test]
fn hosts_are_clean_under_address_and_undefined_behaviour_sanitizers() {
    let flags = [
        "-g",
        "-O1",
        "-fsanitize=address,undefined",
        "-fno-sanitize-recover=all",
        "-fno-omit-frame-pointer",
    ];
    for (source, std) in [("minimal.c", "c99"), ("cornell.cpp", "c++17")] {
        let host = HostRun {
            source,
            std,
            args: &[],
        };
        let exe = host.build("asan", &flags);
        run_and_check(&exe, &format!("{source}_asan"));
    }
    let cpp20 = HostRun {
        std: "c++20",
        ..CHECKED_HOSTS[2]
    };
    for host in CHECKED_HOSTS.into_iter().chain([cpp20, STRESS]) {
        let tag = format!("asan_{}", host.std.replace('+', "p"));
        let exe = host.build(&tag, &flags);
        let output = Command::new(&exe)
            .args(host.args(&tag))
            .env("ASAN_OPTIONS", "detect_leaks=1:halt_on_error=1")
            .env("UBSAN_OPTIONS", "print_stacktrace=1:halt_on_error=1")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            output.status.success()
                && !stderr.contains("Sanitizer")
                && !stderr.contains("runtime error"),
            "{} under the sanitizers ({}):\n{}\n{stderr}",
            host.source,
            output.status,
            String::from_utf8_lossy(&output.stdout),
        );
    }
}

/// The C and C++ hosts under valgrind's memcheck, which sees every memory access, mlt's
/// Rust code included: no invalid read or write, no use of uninitialized memory, and no
/// definite, indirect or possible leak (c_examples/valgrind.supp names the few "possible"
/// blocks the C and Rust runtimes keep on purpose, none of mlt's).
#[test]
fn hosts_are_clean_under_valgrind_memcheck() {
    let version = Command::new("valgrind").arg("--version").output();
    assert!(
        version.is_ok_and(|v| v.status.success()),
        "valgrind is needed for this test: apt-get install valgrind"
    );
    let suppressions = crate_dir().join("c_examples").join("valgrind.supp");
    for host in CHECKED_HOSTS {
        let exe = host.build("memcheck", &["-g", "-O1"]);
        let output = Command::new("valgrind")
            .args([
                "--tool=memcheck",
                "--leak-check=full",
                "--show-leak-kinds=definite,indirect,possible",
                "--errors-for-leak-kinds=definite,indirect,possible",
                "--error-exitcode=99",
                // Valgrind runs one thread at a time; with its default unfair lock the
                // render's workers can starve the host thread that polls progress (a cancel
                // after 3 progress calls took over 30 s on a 2-core machine).
                "--fair-sched=yes",
            ])
            .arg(format!("--suppressions={}", suppressions.display()))
            .arg(&exe)
            .args(host.args("memcheck"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            output.status.success() && stderr.contains("ERROR SUMMARY: 0 errors"),
            "{} under memcheck ({}):\n{stderr}",
            host.source,
            output.status,
        );
    }
}

/// The fenced code blocks of the README in `language`, in order.
fn readme_blocks(language: &str) -> Vec<String> {
    let readme = std::fs::read_to_string(crate_dir().join("README.md")).expect("README.md");
    let fence = format!("```{language}\n");
    let mut blocks = Vec::new();
    let mut rest = readme.as_str();
    while let Some(start) = rest.find(&fence) {
        let body = &rest[start + fence.len()..];
        let end = body.find("```").expect("a closed code block");
        blocks.push(body[..end].to_string());
        rest = &body[end..];
    }
    blocks
}

/// Builds the README's only example in `language` (as C, or as C++ in `std`), runs it and
/// checks that it prints the centre pixel of its square light: radiance 1.
fn readme_example_renders(language: &str, as_cpp: bool, std: &str) {
    let blocks = readme_blocks(language);
    assert_eq!(blocks.len(), 1, "the README has one {language} example");
    let source = scratch_dir().join(format!("readme.{language}"));
    std::fs::write(&source, &blocks[0]).unwrap();
    // `compile` takes sources under c_examples/; an absolute path replaces that folder.
    let exe = build(
        source.to_str().unwrap(),
        &format!("readme_{language}"),
        as_cpp,
        &[std],
    );
    let output = Command::new(&exe).output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "the README's {language} example failed ({}):\n{stdout}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        stdout.contains("centre pixel 1.000"),
        "the README's {language} example printed:\n{stdout}"
    );
}

#[test]
fn readme_c_example_renders() {
    readme_example_renders("c", false, "-std=c99");
}

#[test]
fn readme_cpp_example_renders() {
    readme_example_renders("cpp", true, "-std=c++17");
}
