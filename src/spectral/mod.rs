//! Spectral transport (issue 19, in progress): the wavelengths a camera path carries.
//! Not yet used by the integrators.
// Until the integrators use it.
#![cfg_attr(not(test), allow(dead_code))]

mod cie;
mod cie_data;
mod color;
mod rgb_to_spectrum;
mod wavelengths;

#[allow(unused_imports)]
pub(crate) use cie::{cie_1931_xyz, d65};
#[allow(unused_imports)]
pub(crate) use color::{d65_white, linear_srgb_from_xyz, xyz_from_linear_srgb};
#[allow(unused_imports)]
pub(crate) use rgb_to_spectrum::{SigmoidPolynomial, reflectance_coefficients};
#[allow(unused_imports)]
pub(crate) use wavelengths::{
    LAMBDA_MAX, LAMBDA_MIN, SampledWavelengths, WAVELENGTHS, visible_wavelength_pdf,
};
