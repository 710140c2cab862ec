//! # mlt — an embeddable Metropolis Light Transport kernel
//!
//! Hand it triangles, materials and a camera; get back a linear HDR image. C and C++ hosts use
//! the same kernel through `include/mlt.h` (the exports are in [`capi`]).
//!
//! The Rust API is what the crate root exports:
//! - the scene: a [`SceneDesc`] (positions, indices, [`Material`]s, [`TextureDesc`]s,
//!   [`LightsDesc`] with its [`EnvironmentDesc`], [`SunDesc`] and [`PunctualLight`]s) that
//!   [`Scene::new`] validates and builds;
//! - the render: a [`Camera`] and [`RenderSettings`] (an [`Algorithm`], its
//!   [`MutationWeights`], …) that [`render()`] turns into an image and [`RenderStats`] (with
//!   [`NormalizationStats`], [`FilterStats`], a [`StopReason`]);
//! - [`params`]: the settings by name, with each one's type, default, range and doc (what
//!   the command line and the Python package are built from);
//! - [`jobs`]: a render planned, split into jobs for many machines and merged;
//! - [`error`]: the [`Error`] every call returns, with the [`MltStatus`] C hosts get;
//! - `io` (the `cli` feature, on by default): scene files, camera files, images.
//!
//! The `internals` feature makes the kernel's modules public for this crate's tests, benches
//! and examples; they are not part of the API and change without notice.
//!
//! ```
//! use mlt::{Camera, Material, RenderSettings, Scene, SceneDesc};
//! // One emissive quad facing the camera.
//! let positions = [-1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0];
//! let indices = [0, 2, 1, 0, 3, 2];
//! let materials = [Material::diffuse([0.5; 3]).with_emission([1.0; 3])];
//! let scene = Scene::new(&SceneDesc {
//!     positions: &positions,
//!     indices: &indices,
//!     material_ids: &[],
//!     materials: &materials,
//!     lights: Default::default(),
//!     backend: Default::default(),
//!     ..Default::default()
//! })
//! .unwrap();
//! let camera = Camera { eye: [0.0, 0.0, -3.0], target: [0.0; 3], ..Camera::default() };
//! let settings = RenderSettings { width: 8, height: 8, samples_per_pixel: 4, ..Default::default() };
//! let mut image = vec![0.0f32; 8 * 8 * 3];
//! mlt::render(&scene, &camera, &settings, &mut image, None).unwrap();
//! assert!((image[(4 * 8 + 4) * 3] - 1.0).abs() < 1e-6);
//! ```

// The kernel's internals are crate-private. The `internals` feature (unstable, for this
// crate's tests, benches and examples) makes some of them public and hides them from the
// docs. cbindgen reads the private declaration only (it skips `cbindgen:ignore`), so it finds
// the header's constants once.
#[cfg(feature = "internals")]
#[doc(hidden)]
/// cbindgen:ignore
pub mod accel;
#[cfg(not(feature = "internals"))]
mod accel;
#[cfg(feature = "internals")]
#[doc(hidden)]
/// cbindgen:ignore
pub mod bsdf;
#[cfg(not(feature = "internals"))]
mod bsdf;
pub mod capi;
mod control;
pub mod error;
#[cfg(feature = "internals")]
#[doc(hidden)]
/// cbindgen:ignore
pub mod film;
#[cfg(not(feature = "internals"))]
mod film;
mod filter;
#[cfg(feature = "internals")]
#[doc(hidden)]
/// cbindgen:ignore
pub mod integrators;
#[cfg(not(feature = "internals"))]
mod integrators;
mod interaction;
pub mod params;
#[cfg(feature = "internals")]
#[doc(hidden)]
/// cbindgen:ignore
pub mod render;
#[cfg(not(feature = "internals"))]
mod render;
#[cfg(feature = "internals")]
#[doc(hidden)]
/// cbindgen:ignore
pub mod sampling;
#[cfg(not(feature = "internals"))]
mod sampling;
#[cfg(feature = "internals")]
#[doc(hidden)]
/// cbindgen:ignore
pub mod scene;
#[cfg(not(feature = "internals"))]
mod scene;
mod spectral;
#[cfg(feature = "internals")]
#[doc(hidden)]
/// cbindgen:ignore
pub mod spectrum;
#[cfg(not(feature = "internals"))]
mod spectrum;
mod texture;
mod wire;

#[cfg(feature = "cli")]
pub mod io;

pub use accel::{Backend, BuildQuality};
pub use error::{Error, MltStatus, Result};
pub use filter::{
    FilterStats, MLT_MAX_FILTER_BUFFERS, MLT_MAX_FILTER_RADIUS, MLT_MAX_FILTER_STRENGTH,
    MLT_MIN_FILTER_BUFFERS,
};
pub use integrators::mlt::driver::{Mutation, MutationCounts, MutationWeights};
pub use integrators::mlt::normalization::NormalizationStats;
pub use render::jobs;
pub use render::{
    Algorithm, MLT_MAX_BOOTSTRAP_SAMPLES, MLT_MAX_DEPTH_LIMIT, MLT_MAX_ERPT_CHAIN_LENGTH,
    MLT_MAX_ERPT_DEPOSIT_ENERGY, MLT_MAX_IMAGE_SIDE, MLT_MAX_NORMALIZATION_WORK_FRACTION,
    MLT_MAX_SAMPLES_PER_PIXEL, MLT_MAX_THREADS, MLT_MAX_TIME_LIMIT_SECONDS, Progress,
    RenderSettings, RenderStats, StopReason, render, render_with_unfiltered,
};
pub use scene::{
    AlphaMode, Camera, EnvironmentDesc, LightsDesc, MLT_MAX_ENVIRONMENT_SIDE,
    MLT_MAX_ENVIRONMENT_TEXELS, MLT_MAX_PUNCTUAL_LIGHTS, Material, MaterialKind, PunctualLight,
    PunctualLightKind, Scene, SceneDesc, SceneInfo, SunDesc, TextureRef,
};
pub use spectral::white_light_srgb_per_nm;
pub use texture::{
    MLT_MAX_TEXTURE_SIDE, MLT_MAX_TEXTURE_TEXELS, TexelData, TextureDesc, TextureEncoding,
    TextureFilter, WrapMode,
};

/// The README's Rust example, run as a doctest so that it stays true to the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeExample;

// One scene serves renders and queries from many threads at once.
const _: () = {
    const fn shareable<T: Send + Sync>() {}
    shareable::<Scene>();
};
