//! The C and C++ compilers of the tests that build hosts against mlt's headers.

/// The C (or C++) compiler the `cc` crate would use for this platform: honours CC / CXX and
/// friends. `cc` normally reads TARGET, HOST and OPT_LEVEL from a build script's environment;
/// here they are set explicitly. If cc cannot decide, fall back to `cc` / `c++` on PATH.
pub fn compiler(cpp: bool) -> std::process::Command {
    let triple = host_triple();
    let tool = triple.and_then(|t| {
        cc::Build::new()
            .cargo_metadata(false)
            .cargo_warnings(false)
            .emit_rerun_if_env_changed(false)
            .opt_level(0)
            .debug(false)
            .target(t)
            .host(t)
            .cpp(cpp)
            .try_get_compiler()
            .ok()
    });
    match tool {
        Some(tool) => tool.to_command(),
        None => std::process::Command::new(if cpp { "c++" } else { "cc" }),
    }
}

/// The target triple this test was compiled for, for the common platforms.
pub fn host_triple() -> Option<&'static str> {
    use std::env::consts::{ARCH, OS};
    let env_gnu = cfg!(target_env = "gnu");
    Some(match (ARCH, OS) {
        ("x86_64", "linux") if env_gnu => "x86_64-unknown-linux-gnu",
        ("aarch64", "linux") if env_gnu => "aarch64-unknown-linux-gnu",
        ("x86_64", "linux") => "x86_64-unknown-linux-musl",
        ("aarch64", "linux") => "aarch64-unknown-linux-musl",
        ("x86_64", "macos") => "x86_64-apple-darwin",
        ("aarch64", "macos") => "aarch64-apple-darwin",
        ("x86_64", "freebsd") => "x86_64-unknown-freebsd",
        _ => return None,
    })
}
