//! The 8-wide node's box test, with AVX2 and FMA: each slab of the eight children's boxes in
//! one fused multiply-subtract. x86-64 only, and only for CPUs that have both: its functions
//! are `#[target_feature]`, and 8-wide trees are only built where the CPU has the features.

use super::layout::{Node8, near_and_far_bounds};
use super::stack::Lanes;
use crate::accel::ray::Ray;
use glam::Vec3A;
use std::arch::x86_64::*;

#[inline]
#[target_feature(enable = "avx2,fma")]
fn load(row: &[f32; 8]) -> __m256 {
    // SAFETY: reads the eight floats `row` refers to (unaligned load, no alignment needed).
    unsafe { _mm256_loadu_ps(row.as_ptr()) }
}

impl Lanes<8> for __m256 {
    #[inline(always)]
    fn lanes(self) -> [f32; 8] {
        // SAFETY: both are 32 bytes of eight f32, and every bit pattern is a valid f32.
        unsafe { std::mem::transmute::<__m256, [f32; 8]>(self) }
    }

    #[inline(always)]
    fn places(self, mask: u32) -> [u32; 8] {
        // SAFETY: eight-lane distances only come from the 8-wide traversal, which runs only
        // on CPUs with AVX2 (`BvhWidth::Eight`).
        unsafe { places8(self, mask) }
    }
}

/// `Lanes::places` with AVX2: the keys (`distance_key`) of lanes outside `mask` are made
/// the least, so that they count for no lane, then each lane's key is compared with all.
#[inline]
#[target_feature(enable = "avx2")]
fn places8(t: __m256, mask: u32) -> [u32; 8] {
    let lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let keys = _mm256_or_si256(
        _mm256_and_si256(_mm256_castps_si256(t), _mm256_set1_epi32(!7)),
        lanes,
    );
    let bits = _mm256_sllv_epi32(_mm256_set1_epi32(1), lanes);
    let in_mask = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask as i32), bits), bits);
    let keys = _mm256_blendv_epi8(_mm256_set1_epi32(i32::MIN), keys, in_mask);
    let mut farther = _mm256_setzero_si256();
    for other in 0..8 {
        let key = _mm256_permutevar8x32_epi32(keys, _mm256_set1_epi32(other));
        // Lanes where `other`'s key is larger get -1.
        farther = _mm256_sub_epi32(farther, _mm256_cmpgt_epi32(key, keys));
    }
    let places = _mm256_blendv_epi8(_mm256_set1_epi32(7), farther, in_mask);
    // SAFETY: both are 32 bytes of eight 32-bit integers.
    unsafe { std::mem::transmute::<__m256i, [u32; 8]>(places) }
}

/// `BoxRay4` for eight boxes, with each slab computed as one fused bound · inv − origin · inv.
///
/// For a zero direction component (inv = ±inf) the fused form gives the slab's ±inf only
/// when the bound and the origin have opposite signs, and NaN otherwise (inf − inf, or
/// 0 · inf). NaN slabs leave the interval unconstrained, as in `BoxRay4`: such a ray is
/// culled by the other two axes only, never wrongly. A direction of all zeros would leave
/// empty slots unculled, so such rays are answered before the traversal.
pub(super) struct BoxRay8 {
    near: [usize; 3],
    far: [usize; 3],
    inv_direction: [__m256; 3],
    origin_inv: [__m256; 3],
}

impl BoxRay8 {
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn new(ray: &Ray) -> Self {
        let inv = Vec3A::ONE / ray.direction;
        // Where origin · inv overflows (a direction component tiny against the origin's),
        // a box's far slab bound · inv − origin · inv would be −inf even for a box the ray
        // enters: the ray is taken as parallel to that axis (inv = ±inf), whose slabs are
        // ±inf or NaN as above, never a wrong bound.
        let inv = Vec3A::select(
            (ray.origin * inv).is_finite_mask(),
            inv,
            Vec3A::INFINITY.copysign(inv),
        );
        let origin_inv = ray.origin * inv;
        let (near, far) = near_and_far_bounds(inv);
        BoxRay8 {
            near,
            far,
            inv_direction: inv.to_array().map(|v| _mm256_set1_ps(v)),
            origin_inv: origin_inv.to_array().map(|v| _mm256_set1_ps(v)),
        }
    }

    /// Entry distances of the eight children and which of them the ray enters in
    /// [tmin, tmax]. The running value is the second operand of max/min, which vmaxps and
    /// vminps return when the first is NaN.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn intersect(&self, node: &Node8, tmin: f32, tmax: f32) -> (__m256, u32) {
        let slab = |bound: usize, axis: usize| {
            _mm256_fmsub_ps(
                load(&node.bounds[bound]),
                self.inv_direction[axis],
                self.origin_inv[axis],
            )
        };
        let t_near = _mm256_max_ps(
            slab(self.near[2], 2),
            _mm256_max_ps(
                slab(self.near[1], 1),
                _mm256_max_ps(slab(self.near[0], 0), _mm256_set1_ps(tmin)),
            ),
        );
        let t_far = _mm256_min_ps(
            slab(self.far[2], 2),
            _mm256_min_ps(
                slab(self.far[1], 1),
                _mm256_min_ps(slab(self.far[0], 0), _mm256_set1_ps(tmax)),
            ),
        );
        let entered = _mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far);
        (t_near, _mm256_movemask_ps(entered) as u32)
    }
}
