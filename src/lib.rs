//! # mlt — an embeddable Metropolis Light Transport kernel
//!
//! Hand it triangles, materials and a camera; get back a linear HDR image. The Rust API is
//! [`Scene::new`] and [`render()`]; C and C++ hosts use the same kernel through `include/mlt.h`
//! (see [`capi`]).
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

pub mod accel;
pub mod bsdf;
pub mod capi;
mod control;
pub mod error;
pub mod film;
pub mod filter;
pub mod integrators;
mod interaction;
pub mod params;
pub mod render;
pub mod sampling;
pub mod scene;
mod spectral;
pub mod spectrum;
mod texture;
mod wire;

#[cfg(feature = "cli")]
pub mod io;

pub use accel::{Backend, BuildQuality};
pub use error::{Error, MltStatus, Result};
pub use filter::FilterStats;
pub use integrators::mlt::driver::{Mutation, MutationCounts, MutationWeights};
pub use integrators::mlt::normalization::NormalizationStats;
pub use render::jobs;
pub use render::{
    Algorithm, RenderSettings, RenderStats, StopReason, render, render_with_unfiltered,
};
pub use scene::{
    AlphaMode, Camera, EnvironmentDesc, LightsDesc, Material, MaterialKind, PunctualLight,
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
