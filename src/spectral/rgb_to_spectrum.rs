//! TEMPORARY STUB (replaced by the sigmoid-polynomial fit): grey of the colour's mean.
pub(crate) struct SigmoidPolynomial(f32);
impl SigmoidPolynomial {
    pub(crate) fn eval(&self, _lambda: f32) -> f32 {
        self.0
    }
}
pub(crate) fn reflectance_coefficients(rgb: [f32; 3]) -> SigmoidPolynomial {
    SigmoidPolynomial((rgb[0] + rgb[1] + rgb[2]) / 3.0)
}
