//! The colour a path carries: radiance, emission, reflectance, BSDF values, throughput and
//! path contributions are all a [`Spectrum`].
//!
//! Colour has a type of its own, not the `Vec3A` of positions and directions, so that a
//! colour cannot be mixed up with a point and so that every piece of colour arithmetic goes
//! through this one definition. A spectrum is four lanes of a `Vec4` (its SIMD arithmetic,
//! one operation per lane). What the lanes mean is the path's [`Channels`]
//! (`crate::spectral`): in RGB mode linear R, G, B and G once more — the fourth lane
//! repeats the green so that every lane-wise operation, division included, stays as
//! defined as on the three channels, and RGB results are those of three-channel
//! arithmetic; in spectral mode the radiance at the path's four sampled wavelengths.
//!
//! Where colour leaves the kernel it becomes plain RGB again (`Channels::rgb_of`): the
//! film and the filter keep `f32`/`f64` triples (`to_array`, indexing), the C ABI and the
//! Rust API take and give `[f32; 3]`.
//!
//! [`Channels`]: crate::spectral::Channels
//!
//! A leaf module: it depends on glam only.

use glam::{Vec3A, Vec4};
use std::fmt;
use std::ops::{Add, AddAssign, Div, DivAssign, Index, Mul, MulAssign, Sub, SubAssign};

/// Rec. 709 weights of linear R, G and B in luminance (the Y of CIE XYZ): the one
/// definition of luminance. [`Spectrum::luminance`] applies them to a spectrum; the crate
/// uses them directly only for the film's `f64` RGB sums, which are not spectra. (Not
/// `pub`: cbindgen would put a public constant in `include/mlt.h`.)
pub(crate) const LUMINANCE_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// The weights in `f32` (each rounds to the same `f32` as its decimal literal).
const LUMINANCE_WEIGHTS_F32: Vec3A = Vec3A::new(
    LUMINANCE_WEIGHTS[0] as f32,
    LUMINANCE_WEIGHTS[1] as f32,
    LUMINANCE_WEIGHTS[2] as f32,
);

/// A colour quantity: four `f32` lanes, linear RGB (and green again) or the values at four
/// wavelengths.
#[derive(Clone, Copy, Default, PartialEq)]
#[repr(transparent)]
pub struct Spectrum(Vec4);

impl Spectrum {
    /// Black: no light, no reflectance.
    pub const ZERO: Spectrum = Spectrum(Vec4::ZERO);
    /// One in every lane: the throughput a path starts with.
    pub const ONE: Spectrum = Spectrum(Vec4::ONE);

    /// The RGB spectrum with channels `r`, `g`, `b`.
    #[inline]
    pub const fn new(r: f32, g: f32, b: f32) -> Spectrum {
        Spectrum(Vec4::new(r, g, b, g))
    }

    /// The spectrum with these four lanes (values at four wavelengths).
    #[inline]
    pub(crate) const fn from_lanes(lanes: [f32; 4]) -> Spectrum {
        Spectrum(Vec4::from_array(lanes))
    }

    /// `v` in every lane (a grey).
    #[inline]
    pub const fn splat(v: f32) -> Spectrum {
        Spectrum(Vec4::splat(v))
    }

    /// The first three lanes: the channels of an RGB spectrum.
    #[inline]
    pub fn to_array(self) -> [f32; 3] {
        [self.0.x, self.0.y, self.0.z]
    }

    /// All four lanes.
    #[inline]
    pub(crate) const fn lanes(self) -> [f32; 4] {
        self.0.to_array()
    }

    /// `f` applied to every lane (a non-linear function of a colour, channel by channel).
    #[inline]
    pub(crate) fn map(self, f: impl Fn(f32) -> f32) -> Spectrum {
        Spectrum(self.0.map(f))
    }

    /// Luminance (Rec. 709, `LUMINANCE_WEIGHTS`) of an RGB spectrum: the scalar of a
    /// colour, by which lights are picked and Metropolis chains are distributed. (A
    /// spectrum at wavelengths has its luminance through `Channels::luminance`.)
    #[inline]
    pub fn luminance(self) -> f32 {
        // The three channels' dot product, summed in the order `Vec3A` sums it (the
        // fourth lane, a copy of green, weighs nothing).
        Vec3A::from_vec4(self.0).dot(LUMINANCE_WEIGHTS_F32)
    }

    /// The largest lane (Russian roulette's survival, tests for black).
    #[inline]
    pub fn max_component(self) -> f32 {
        self.0.max_element()
    }

    /// Whether no channel is positive: colours are never negative, so whether it is zero.
    #[inline]
    pub fn is_black(self) -> bool {
        self.max_component() <= 0.0
    }

    /// Whether every channel is finite (neither NaN nor infinite).
    #[inline]
    pub fn is_finite(self) -> bool {
        self.0.is_finite()
    }

    /// The absolute value of every channel.
    #[inline]
    pub fn abs(self) -> Spectrum {
        Spectrum(self.0.abs())
    }

    /// The larger of the two in every channel.
    #[inline]
    pub fn max(self, other: Spectrum) -> Spectrum {
        Spectrum(self.0.max(other.0))
    }

    /// The smaller of the two in every channel.
    #[inline]
    pub fn min(self, other: Spectrum) -> Spectrum {
        Spectrum(self.0.min(other.0))
    }
}

impl From<[f32; 3]> for Spectrum {
    /// The RGB spectrum of linear RGB channels (materials' colours and emission).
    #[inline]
    fn from([r, g, b]: [f32; 3]) -> Spectrum {
        Spectrum::new(r, g, b)
    }
}

impl Index<usize> for Spectrum {
    type Output = f32;
    /// Lane `index` (0, 1, 2: R, G, B of an RGB spectrum; 3 repeats G).
    #[inline]
    fn index(&self, index: usize) -> &f32 {
        &self.0[index]
    }
}

impl fmt::Debug for Spectrum {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut tuple = f.debug_tuple("Spectrum");
        for lane in self.lanes() {
            tuple.field(&lane);
        }
        tuple.finish()
    }
}

impl fmt::Display for Spectrum {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.0, f)
    }
}

/// `impl $trait for Spectrum` (and its `…Assign`), lane by lane, by `Vec4`'s.
macro_rules! channelwise {
    ($trait:ident $method:ident, $assign:ident $assign_method:ident) => {
        impl $trait for Spectrum {
            type Output = Spectrum;
            #[inline]
            fn $method(self, rhs: Spectrum) -> Spectrum {
                Spectrum(self.0.$method(rhs.0))
            }
        }
        impl $assign for Spectrum {
            #[inline]
            fn $assign_method(&mut self, rhs: Spectrum) {
                self.0.$assign_method(rhs.0)
            }
        }
    };
}

channelwise!(Add add, AddAssign add_assign);
channelwise!(Sub sub, SubAssign sub_assign);
channelwise!(Mul mul, MulAssign mul_assign);
channelwise!(Div div, DivAssign div_assign);

/// `impl $trait<f32> for Spectrum` (and its `…Assign`): every channel with the scalar.
macro_rules! scalar {
    ($trait:ident $method:ident, $assign:ident $assign_method:ident) => {
        impl $trait<f32> for Spectrum {
            type Output = Spectrum;
            #[inline]
            fn $method(self, rhs: f32) -> Spectrum {
                Spectrum(self.0.$method(rhs))
            }
        }
        impl $assign<f32> for Spectrum {
            #[inline]
            fn $assign_method(&mut self, rhs: f32) {
                self.0.$assign_method(rhs)
            }
        }
    };
}

scalar!(Mul mul, MulAssign mul_assign);
scalar!(Div div, DivAssign div_assign);

impl Mul<Spectrum> for f32 {
    type Output = Spectrum;
    #[inline]
    fn mul(self, rhs: Spectrum) -> Spectrum {
        Spectrum(self * rhs.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On RGB spectra the operators are three-channel (`Vec3A`) arithmetic, bit for bit,
    /// in the order they are written, and the fourth lane stays a copy of green.
    #[test]
    fn arithmetic_is_vec3a_arithmetic() {
        let (a, b, c) = ([0.3f32, 1.7, 2.9], [0.11f32, 7.3, 0.013], 0.37f32);
        let (sa, sb) = (Spectrum::from(a), Spectrum::from(b));
        let (va, vb) = (Vec3A::from(a), Vec3A::from(b));
        let bits = |s: Spectrum| s.to_array().map(f32::to_bits);
        let vbits = |v: Vec3A| v.to_array().map(f32::to_bits);
        assert_eq!(bits(sa * sb * c), vbits(va * vb * c));
        assert_eq!(bits(c * sa), vbits(c * va));
        assert_eq!(bits(sa / c), vbits(va / c));
        assert_eq!(bits(sa / sb), vbits(va / vb));
        assert_eq!(bits(sa + sb - sa), vbits(va + vb - va));
        let (mut s, mut v) = (sa, va);
        s *= sb;
        v *= vb;
        s /= c;
        v /= c;
        s += sa;
        v += va;
        s *= c;
        v *= c;
        s -= sb;
        v -= vb;
        assert_eq!(bits(s), vbits(v));
        assert_eq!(s[3].to_bits(), s[1].to_bits());
        assert_eq!((sa / sb)[3].to_bits(), (sa / sb)[1].to_bits());
        assert_eq!(
            sa.luminance().to_bits(),
            va.dot(Vec3A::new(0.2126, 0.7152, 0.0722)).to_bits()
        );
    }

    #[test]
    fn queries() {
        let s = Spectrum::new(0.25, -1.0, 0.5);
        assert_eq!(s.max_component(), 0.5);
        assert_eq!((s[0], s[1], s[2]), (0.25, -1.0, 0.5));
        assert_eq!(s.abs().to_array(), [0.25, 1.0, 0.5]);
        assert_eq!(s.max(Spectrum::ZERO).to_array(), [0.25, 0.0, 0.5]);
        assert!(Spectrum::ZERO.is_black() && !Spectrum::ONE.is_black());
        assert!(s.is_finite() && !Spectrum::splat(f32::NAN).is_finite());
        assert!((Spectrum::ONE.luminance() - 1.0).abs() < 1e-6);
        assert_eq!(Spectrum::splat(2.0), Spectrum::new(2.0, 2.0, 2.0));
        assert_eq!(
            format!("{:?}", Spectrum::ONE),
            "Spectrum(1.0, 1.0, 1.0, 1.0)"
        );
        assert_eq!(s.map(|x| 2.0 * x).to_array(), [0.5, -2.0, 1.0]);
        assert_eq!(
            Spectrum::from_lanes([1.0, 2.0, 3.0, 4.0]).lanes(),
            [1.0, 2.0, 3.0, 4.0]
        );
    }
}
