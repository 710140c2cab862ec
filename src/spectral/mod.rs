//! Spectral transport (`RenderSettings::spectral`): the wavelengths a camera path carries
//! (`wavelengths.rs`), the CIE tables (`cie.rs`), the conversions between RGB and spectra
//! (`rgb_to_spectrum.rs`, `color.rs`) and what a path's spectrum lanes mean
//! (`channels.rs`, the one type the rest of the crate uses).

mod channels;
mod cie;
mod cie_data;
mod color;
mod rgb_to_spectrum;
mod wavelengths;

pub use channels::white_light_srgb_per_nm;
pub(crate) use channels::{Channels, FittedColour};
pub(crate) use wavelengths::SampledWavelengths;
