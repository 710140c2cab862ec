//! Generates `include/mlt.h` from the C ABI with cbindgen. The header is committed; CI
//! rebuilds it and fails if `git diff` shows it changed. The header is the same with and
//! without the `embree` feature: the C ABI has no feature-dependent items.
//!
//! With the `embree` feature, links the system's Embree 3 (`libembree3`).
//!
//! On Linux the shared library gets the soname `libmlt.so.<major>`, so hosts record that name
//! and a later compatible library (the C ABI only grows, checked by `struct_size`) replaces it
//! in place. `cmake --install` (CMakeLists.txt) installs it as `libmlt.so.<version>` with the
//! `libmlt.so.<major>` and `libmlt.so` links.

use std::path::PathBuf;

fn main() {
    let crate_dir = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=cbindgen.toml");
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_EMBREE").is_some() {
        println!("cargo:rustc-link-lib=embree3");
    }
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        let major = std::env::var("CARGO_PKG_VERSION_MAJOR").unwrap();
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libmlt.so.{major}");
    }

    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml"))
        .expect("cbindgen.toml is readable and valid");
    let bindings = match cbindgen::Builder::new()
        .with_crate(&crate_dir)
        .with_config(config)
        .generate()
    {
        Ok(bindings) => bindings,
        Err(error) => {
            // A syntax error in src/ is reported better by rustc; don't fail here.
            println!("cargo:warning=cbindgen could not generate mlt.h: {error}");
            return;
        }
    };
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    bindings.write_to_file(out_dir.join("mlt.h"));
    // Update the committed header only when it changed, so its mtime means something and a
    // read-only source tree (a packaged crate) still builds.
    let header = crate_dir.join("include").join("mlt.h");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    if std::fs::read(&header).ok().as_deref() != Some(&generated[..])
        && let Err(error) = std::fs::create_dir_all(header.parent().unwrap())
            .and_then(|_| std::fs::write(&header, &generated))
    {
        println!(
            "cargo:warning=could not update {}: {error}",
            header.display()
        );
    }
}
