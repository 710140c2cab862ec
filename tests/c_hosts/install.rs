//! mlt installed as a C library: the top-level CMakeLists.txt installs into a prefix under the
//! target directory the libraries `cargo test` built next to this test's executable
//! (`MLT_PREBUILT_DIR`: a cargo build run from here would compile everything again, since
//! cargo test resolves the dependencies' features with the dev-dependencies), and hosts find
//! it the ways the README shows: pkg-config for a C program (shared and static) and CMake's
//! `find_package(mlt 0.1 CONFIG REQUIRED)` for a C++ project (c_examples/cmake_consumer).
//! Their images must be the Rust API's, bit for bit.

use super::{compile, crate_dir, run_and_check, scratch_dir};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

const VERSION: &str = env!("CARGO_PKG_VERSION");
const SONAME: &str = concat!("libmlt.so.", env!("CARGO_PKG_VERSION_MAJOR"));

/// Runs `cmd`; panics with its output unless it succeeds.
fn run(cmd: &mut Command) -> Output {
    let output = cmd
        .output()
        .unwrap_or_else(|e| panic!("could not run {cmd:?}: {e}"));
    assert!(
        output.status.success(),
        "{cmd:?} failed ({}):\n{}{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Fails, rather than skips, when a tool the installed way needs is missing.
fn require(tool: &str) {
    if Command::new(tool).arg("--version").output().is_err() {
        panic!(
            "{tool} is not installed, and the install tests need it: \
             apt-get install cmake pkg-config (as .ci/run does)"
        );
    }
}

/// `target/<profile>/deps/`, where `cargo test` put the static and shared libraries it
/// compiled along with the rlib linked into this test.
fn built_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().unwrap().to_path_buf()
}

fn install_root() -> PathBuf {
    scratch_dir().join("install")
}

/// Configures, builds and installs mlt into a fresh prefix, once per test process.
fn prefix() -> &'static Path {
    static PREFIX: OnceLock<PathBuf> = OnceLock::new();
    PREFIX.get_or_init(|| {
        require("cmake");
        let build = install_root().join("build");
        let prefix = install_root().join("prefix");
        for dir in [&build, &prefix] {
            let _ = std::fs::remove_dir_all(dir);
        }
        run(Command::new("cmake")
            .arg("-S")
            .arg(crate_dir())
            .arg("-B")
            .arg(&build)
            .arg(format!("-DCMAKE_INSTALL_PREFIX={}", prefix.display()))
            // GNUInstallDirs picks lib64 on some systems; the tests look in lib.
            .arg("-DCMAKE_INSTALL_LIBDIR=lib")
            .arg(format!("-DMLT_PREBUILT_DIR={}", built_dir().display()))
            .arg(format!(
                "-DMLT_EMBREE={}",
                if cfg!(feature = "embree") {
                    "ON"
                } else {
                    "OFF"
                }
            )));
        run(Command::new("cmake")
            .arg("--build")
            .arg(&build)
            .args(["--target", "install"]));
        prefix
    })
}

fn libdir() -> PathBuf {
    prefix().join("lib")
}

/// `pkg-config ARGS` with the installed prefix on its path, split into arguments.
fn pkg_config(args: &[&str]) -> Vec<OsString> {
    require("pkg-config");
    let output = run(Command::new("pkg-config")
        .env("PKG_CONFIG_PATH", libdir().join("pkgconfig"))
        .args(args));
    stdout(&output)
        .split_whitespace()
        .map(OsString::from)
        .collect()
}

/// The dynamic section's libraries (NEEDED) and soname of an ELF file, as `readelf -d` says.
fn dynamic_section(file: &Path) -> String {
    stdout(&run(Command::new("readelf").arg("-d").arg(file)))
}

fn needs_libmlt(exe: &Path) -> bool {
    let dynamic = dynamic_section(exe);
    assert!(
        !dynamic.contains("libmlt.so]"),
        "{exe:?} needs the unversioned libmlt.so:\n{dynamic}"
    );
    dynamic.contains(&format!("Shared library: [{SONAME}]"))
}

/// The section headers of an ELF file, or of every member of an archive.
fn sections(file: &Path) -> String {
    stdout(&run(Command::new("readelf").args(["-S", "-W"]).arg(file)))
}

#[test]
fn installed_libraries_are_versioned_and_without_debug_information() {
    let lib = libdir();
    let real = format!("libmlt.so.{VERSION}");
    assert_eq!(
        std::fs::read_link(lib.join(SONAME)).unwrap(),
        Path::new(&real)
    );
    assert_eq!(
        std::fs::read_link(lib.join("libmlt.so")).unwrap(),
        Path::new(&real)
    );
    let dynamic = dynamic_section(&lib.join(&real));
    assert!(
        dynamic.contains(&format!("Library soname: [{SONAME}]")),
        "the soname of {real}:\n{dynamic}"
    );

    // cargo's copies carry the profile's debug information; the installed ones none.
    for (built, installed) in [
        (built_dir().join("libmlt.a"), lib.join("libmlt.a")),
        (built_dir().join("libmlt.so"), lib.join(&real)),
    ] {
        assert!(
            sections(&built).contains(".debug_line"),
            "{built:?} has no debug information to strip"
        );
        let installed_sections = sections(&installed);
        for section in [".debug_", ".llvmbc"] {
            assert!(
                !installed_sections.contains(section),
                "{installed:?} still has {section} sections"
            );
        }
        let size = |file: &Path| std::fs::metadata(file).unwrap().len();
        assert!(
            size(&installed) < size(&built),
            "{installed:?} is not smaller"
        );
    }

    let include = prefix().join("include").join("mlt");
    for header in ["mlt.h", "mlt.hpp"] {
        assert_eq!(
            std::fs::read(include.join(header)).unwrap(),
            std::fs::read(crate_dir().join("include").join(header)).unwrap(),
            "the installed {header}"
        );
    }
}

/// minimal.c through `pkg-config --cflags --libs mlt` (the shared library, found through an
/// rpath) and `mlt-static` (the archive with the system libraries it needs).
#[test]
fn installed_library_links_c_through_pkg_config() {
    let modversion = pkg_config(&["--modversion", "mlt"]);
    assert_eq!(modversion, [OsString::from(VERSION)]);
    // The .pc file's paths are relative to itself (${pcfiledir}): the prefix can move.
    let pc_libdir = pkg_config(&["--variable=libdir", "mlt"]);
    assert_eq!(
        Path::new(&pc_libdir[0]).canonicalize().unwrap(),
        libdir().canonicalize().unwrap()
    );

    let private = pkg_config(&["--static", "--libs", "mlt"]);
    let static_libs = pkg_config(&["--libs", "mlt-static"]);
    for libs in [&private, &static_libs] {
        for lib in ["-lpthread", "-ldl", "-lm"] {
            assert!(libs.contains(&lib.into()), "no {lib} in {libs:?}");
        }
        assert_eq!(
            libs.contains(&"-lembree3".into()),
            cfg!(feature = "embree"),
            "-lembree3 in {libs:?} (the embree feature is {})",
            cfg!(feature = "embree")
        );
    }

    let mut rpath = OsString::from("-Wl,-rpath,");
    rpath.push(libdir());
    let shared_libs = [pkg_config(&["--libs", "mlt"]), vec![rpath]].concat();
    for (package, libs, shared) in [
        ("mlt", shared_libs, true),
        ("mlt-static", static_libs, false),
    ] {
        let name = format!("minimal_{package}");
        let flags = [
            vec![OsString::from("-std=c99")],
            pkg_config(&["--cflags", package]),
        ]
        .concat();
        let exe = compile("minimal.c", &name, false, &flags, &libs);
        assert_eq!(needs_libmlt(&exe), shared, "{name} loads {SONAME}");
        let stdout = run_and_check(&exe, &name);
        assert!(stdout.contains(&format!("mlt {VERSION}")), "{stdout}");
    }
}

/// Configures a throwaway project that calls `find_package(mlt <version> CONFIG REQUIRED)`
/// with the installed prefix and prints what it found.
fn find_package(version: &str) -> Output {
    let dir = install_root().join(format!("find_package_{version}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("CMakeLists.txt"),
        format!(
            "cmake_minimum_required(VERSION 3.16)\n\
             project(find_mlt LANGUAGES NONE)\n\
             find_package(mlt {version} CONFIG REQUIRED)\n\
             get_target_property(libs mlt::mlt_static INTERFACE_LINK_LIBRARIES)\n\
             message(STATUS \"found mlt ${{mlt_VERSION}} embree=${{mlt_EMBREE}} static libs=${{libs}}\")\n"
        ),
    )
    .unwrap();
    Command::new("cmake")
        .arg("-S")
        .arg(&dir)
        .arg("-B")
        .arg(dir.join("build"))
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix().display()))
        .output()
        .unwrap()
}

/// The package's version file: 0.x is compatible with 0.1 and later (the C ABI only grows
/// within a major version), a major version the library is not fails.
#[test]
fn cmake_package_checks_the_version_and_lists_static_dependencies() {
    let found = find_package("0.1");
    let out = stdout(&found);
    assert!(
        found.status.success(),
        "{out}{}",
        String::from_utf8_lossy(&found.stderr)
    );
    let embree = if cfg!(feature = "embree") {
        "ON"
    } else {
        "OFF"
    };
    assert!(
        out.contains(&format!("found mlt {VERSION} embree={embree} static libs=")),
        "{out}"
    );
    assert!(out.contains("-lpthread;"), "{out}");
    assert_eq!(out.contains("-lembree3"), cfg!(feature = "embree"), "{out}");

    let too_new = find_package("1.0");
    let stderr = String::from_utf8_lossy(&too_new.stderr);
    assert!(!too_new.status.success(), "find_package(mlt 1.0) succeeded");
    assert!(
        stderr.contains("considered but not accepted")
            && stderr.contains(&format!("version: {VERSION}")),
        "{stderr}"
    );
}

/// c_examples/cmake_consumer: a C++ project outside the tree that finds the installed mlt
/// with `find_package` and links cornell.cpp to `mlt::mlt` and to `mlt::mlt_static`.
#[test]
fn installed_library_links_cpp_through_cmake_find_package() {
    let build = install_root().join("consumer");
    let _ = std::fs::remove_dir_all(&build);
    run(Command::new("cmake")
        .arg("-S")
        .arg(crate_dir().join("c_examples").join("cmake_consumer"))
        .arg("-B")
        .arg(&build)
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix().display())));
    run(Command::new("cmake").arg("--build").arg(&build));
    for (exe, shared) in [("cornell", true), ("cornell_static", false)] {
        let path = build.join(exe);
        assert_eq!(needs_libmlt(&path), shared, "{exe} loads {SONAME}");
        let name = format!("consumer_{exe}");
        let stdout = run_and_check(&path, &name);
        assert!(stdout.contains("scene: 32 triangles, 2 lights"), "{stdout}");
    }
}
