//! Spectral transport (issue 19, in progress): the wavelengths a camera path carries.
//! Not yet used by the integrators.

mod wavelengths;

#[allow(unused_imports)]
pub(crate) use wavelengths::{
    LAMBDA_MAX, LAMBDA_MIN, SampledWavelengths, WAVELENGTHS, visible_wavelength_pdf,
};
