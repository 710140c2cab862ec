//! From spectra to linear sRGB: a spectrum's CIE XYZ, normalized so that D65 (sRGB's white)
//! has Y = 1, and the XYZ → linear sRGB matrix built from sRGB's primaries and the white
//! point of the tabulated D65 itself. Building it on the white the tables give (0.31272,
//! 0.32903), not the rounded (0.3127, 0.3290) of the sRGB standard's matrix, makes D65 come
//! out exactly as RGB (1, 1, 1): a white surface under a white light stays untinted.

use super::cie::{cie_1931_xyz, d65};
use glam::{DMat3, DVec3};
use std::sync::OnceLock;

/// sRGB's (Rec. 709's) primaries as CIE xy chromaticities.
const PRIMARIES: [[f64; 2]; 3] = [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]];

/// The tabulated D65's XYZ at Y = 1: Σ D65·(x̄, ȳ, z̄) / Σ D65·ȳ at 1 nm.
pub(crate) fn d65_white() -> DVec3 {
    let mut xyz = DVec3::ZERO;
    for lambda in 360..=830 {
        let [x, y, z] = cie_1931_xyz(lambda as f32);
        xyz += DVec3::new(x as f64, y as f64, z as f64) * d65(lambda as f32) as f64;
    }
    xyz / xyz.y
}

/// The matrices between linear sRGB and XYZ: (RGB → XYZ, XYZ → RGB).
fn matrices() -> &'static (DMat3, DMat3) {
    static MATRICES: OnceLock<(DMat3, DMat3)> = OnceLock::new();
    MATRICES.get_or_init(|| {
        // Each primary's XYZ at Y = 1, scaled so that the three add up to the white.
        let columns = PRIMARIES.map(|[x, y]| DVec3::new(x / y, 1.0, (1.0 - x - y) / y));
        let unscaled = DMat3::from_cols(columns[0], columns[1], columns[2]);
        let scale = unscaled.inverse() * d65_white();
        let rgb_to_xyz = unscaled * DMat3::from_diagonal(scale);
        (rgb_to_xyz, rgb_to_xyz.inverse())
    })
}

/// Linear sRGB of the colour `xyz`.
pub(crate) fn linear_srgb_from_xyz(xyz: [f64; 3]) -> [f64; 3] {
    (matrices().1 * DVec3::from(xyz)).into()
}

/// XYZ of the linear sRGB colour `rgb` (what the RGB → spectrum fit aims at).
#[cfg(test)]
pub(crate) fn xyz_from_linear_srgb(rgb: [f64; 3]) -> [f64; 3] {
    (matrices().0 * DVec3::from(rgb)).into()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// D65 is white: (1, 1, 1) exactly (to rounding), and the matrix is the sRGB
    /// standard's up to the white point's rounding (within 2·10⁻³ per entry).
    #[test]
    fn d65_is_white_and_the_matrix_is_srgb() {
        let white = d65_white();
        let rgb = linear_srgb_from_xyz(white.into());
        for c in rgb {
            assert!((c - 1.0).abs() < 1e-9, "{rgb:?}");
        }
        let standard = [
            [3.2406, -1.5372, -0.4986],
            [-0.9689, 1.8758, 0.0415],
            [0.0557, -0.2040, 1.0570],
        ];
        let m = matrices().1;
        for (row, expected) in standard.iter().enumerate() {
            for (col, &e) in expected.iter().enumerate() {
                let got = m.col(col)[row];
                assert!((got - e).abs() < 2e-3, "({row}, {col}): {got} vs {e}");
            }
        }
        // The round trip, and a primary keeps its chromaticity.
        let back = linear_srgb_from_xyz(xyz_from_linear_srgb([0.2, 0.5, 0.9]));
        for (b, e) in back.iter().zip([0.2, 0.5, 0.9]) {
            assert!((b - e).abs() < 1e-12);
        }
        let [x, y, z] = xyz_from_linear_srgb([1.0, 0.0, 0.0]);
        assert!((x / (x + y + z) - 0.64).abs() < 1e-12 && (y / (x + y + z) - 0.33).abs() < 1e-12);
    }
}
