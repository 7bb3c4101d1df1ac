//! Four `f32` lanes with exactly the per-lane IEEE semantics of scalar code.
//!
//! With SSE2 (every `x86_64`) the lanes live in one SSE register, with NEON (every `aarch64`) in
//! one NEON register, elsewhere in a `[f32; 4]`. Every operation is the same IEEE operation in
//! each lane on all three (vector arithmetic rounds as scalar `f32` does, and `min`/`max` are
//! defined as the SSE instructions are, which is how the scalar code writes them; NEON builds
//! them from a compare and a select, as its own `fmin`/`fmax` order signed zeros and NaNs
//! differently), so code written against [`F4`] gives the same bits on every target. Only
//! operations the backends agree on bit for bit belong here.

#[cfg(target_feature = "sse2")]
#[allow(unsafe_code)]
mod sse {
    // SAFETY (every `unsafe` block below): these intrinsics have no precondition beyond the
    // CPU supporting SSE/SSE2, which `cfg(target_feature = "sse2")` guarantees at compile
    // time (it is part of the x86_64 baseline). None of them touches memory. `to_array`'s
    // transmute copies the 16 bytes of an `__m128` into a `[f32; 4]` of the same size, and
    // every bit pattern is a valid `f32`; `clamped_trunc`'s copies an `__m128i` into a
    // `[u32; 4]`, where every bit pattern is valid too.
    use arch::{
        __m128, __m128i, _mm_add_ps, _mm_and_ps, _mm_andnot_ps, _mm_castsi128_ps, _mm_cmple_ps,
        _mm_cvtepi32_ps, _mm_cvtss_f32, _mm_cvttps_epi32, _mm_div_ps, _mm_loadu_si128, _mm_max_ps,
        _mm_min_ps, _mm_movehl_ps, _mm_movemask_ps, _mm_mul_ps, _mm_or_ps, _mm_set1_epi32,
        _mm_set1_ps, _mm_setr_ps, _mm_shuffle_ps, _mm_sub_epi32, _mm_sub_ps, _mm_unpackhi_ps,
        _mm_unpacklo_ps,
    };
    #[cfg(target_arch = "x86")]
    use core::arch::x86 as arch;
    #[cfg(target_arch = "x86_64")]
    use core::arch::x86_64 as arch;

    /// Four lanes in an SSE register.
    #[derive(Clone, Copy)]
    pub(crate) struct F4(__m128);

    impl F4 {
        #[inline(always)]
        pub(crate) fn new(l: [f32; 4]) -> Self {
            Self(unsafe { _mm_setr_ps(l[0], l[1], l[2], l[3]) })
        }
        #[inline(always)]
        pub(crate) fn splat(x: f32) -> Self {
            Self(unsafe { _mm_set1_ps(x) })
        }
        #[inline(always)]
        pub(crate) fn add(self, o: Self) -> Self {
            Self(unsafe { _mm_add_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub(crate) fn sub(self, o: Self) -> Self {
            Self(unsafe { _mm_sub_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub(crate) fn mul(self, o: Self) -> Self {
            Self(unsafe { _mm_mul_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub(crate) fn div(self, o: Self) -> Self {
            Self(unsafe { _mm_div_ps(self.0, o.0) })
        }
        /// The lanes in order.
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 4] {
            unsafe { core::mem::transmute::<__m128, [f32; 4]>(self.0) }
        }
        /// Per lane `a.wrapping_sub(b) as f32` (rounded to nearest).
        #[inline(always)]
        pub(crate) fn from_i32_difference(a: &[i32; 4], b: i32) -> Self {
            // SAFETY: see above; the unaligned load reads the 16 bytes of `a`.
            Self(unsafe {
                let a = _mm_loadu_si128(a.as_ptr().cast::<__m128i>());
                _mm_cvtepi32_ps(_mm_sub_epi32(a, _mm_set1_epi32(b)))
            })
        }
        /// Per lane `|a|`: the sign bit cleared.
        #[inline(always)]
        pub(crate) fn abs(self) -> Self {
            Self(unsafe { _mm_andnot_ps(_mm_set1_ps(-0.0), self.0) })
        }
        /// Per lane `if a < b { a } else { b }` (the second operand when unordered).
        #[inline(always)]
        pub(crate) fn min(self, o: Self) -> Self {
            Self(unsafe { _mm_min_ps(self.0, o.0) })
        }
        /// Per lane `if a > b { a } else { b }` (the second operand when unordered).
        #[inline(always)]
        pub(crate) fn max(self, o: Self) -> Self {
            Self(unsafe { _mm_max_ps(self.0, o.0) })
        }
        /// `[a0, b0, a1, b1]`.
        #[inline(always)]
        pub(crate) fn unpack_lo(self, o: Self) -> Self {
            Self(unsafe { _mm_unpacklo_ps(self.0, o.0) })
        }
        /// `[a2, b2, a3, b3]`.
        #[inline(always)]
        pub(crate) fn unpack_hi(self, o: Self) -> Self {
            Self(unsafe { _mm_unpackhi_ps(self.0, o.0) })
        }
        /// `[a2, a3, a2, a3]`.
        #[inline(always)]
        pub(crate) fn high_half(self) -> Self {
            Self(unsafe { _mm_movehl_ps(self.0, self.0) })
        }
        /// `[a1, a2, a0, a1]`.
        #[inline(always)]
        pub(crate) fn yzx(self) -> Self {
            Self(unsafe { _mm_shuffle_ps::<0b01_00_10_01>(self.0, self.0) })
        }
        /// `[a2, a0, a1, a2]`.
        #[inline(always)]
        pub(crate) fn zxy(self) -> Self {
            Self(unsafe { _mm_shuffle_ps::<0b10_01_00_10>(self.0, self.0) })
        }
        /// `first` if `take_first`, else `second`, without a branch: a mask and two logic
        /// operations, for choices the branch predictor cannot guess.
        #[inline(always)]
        pub(crate) fn select(take_first: bool, first: Self, second: Self) -> Self {
            Self(unsafe {
                let mask = _mm_castsi128_ps(_mm_set1_epi32(-i32::from(take_first)));
                _mm_or_ps(_mm_and_ps(mask, first.0), _mm_andnot_ps(mask, second.0))
            })
        }
        /// Per lane `(x as i32).clamp(0, top)` for a whole `top` in `0..2^31`: the lane clamped
        /// to `[0, top]` (NaN to 0), then truncated (a floor there; exact up to 2^24).
        #[inline(always)]
        pub(crate) fn clamped_trunc(self, top: f32) -> [u32; 4] {
            let x = self.max(Self::splat(0.0)).min(Self::splat(top));
            let bins: __m128i = unsafe { _mm_cvttps_epi32(x.0) };
            unsafe { core::mem::transmute::<__m128i, [u32; 4]>(bins) }
        }
        /// Bit `i` set if lane `i` of `self <= o` (false when unordered).
        #[inline(always)]
        pub(crate) fn le_mask(self, o: Self) -> u32 {
            unsafe { _mm_movemask_ps(_mm_cmple_ps(self.0, o.0)) as u32 }
        }
        /// Bit `i` set if lane `i`'s sign bit is set.
        #[inline(always)]
        pub(crate) fn sign_mask(self) -> u32 {
            unsafe { _mm_movemask_ps(self.0) as u32 }
        }
        #[inline(always)]
        pub(crate) fn lane0(self) -> f32 {
            unsafe { _mm_cvtss_f32(self.0) }
        }
        #[inline(always)]
        pub(crate) fn lane1(self) -> f32 {
            unsafe { _mm_cvtss_f32(_mm_shuffle_ps::<0b01>(self.0, self.0)) }
        }
    }
}

#[cfg(all(target_arch = "aarch64", target_feature = "neon"))]
#[allow(unsafe_code)]
mod neon {
    // SAFETY (every `unsafe` block below): these intrinsics have no precondition beyond the
    // CPU supporting NEON, which `cfg(target_feature = "neon")` guarantees at compile time (it
    // is part of the aarch64 baseline). Only `vld1q_u32` touches memory: it reads the four
    // `u32` of a local array, which is valid, aligned and initialised.
    use core::arch::aarch64::{
        float32x4_t, uint32x4_t, vabsq_f32, vaddq_f32, vaddvq_u32, vandq_u32, vbslq_f32, vcgtq_f32,
        vcleq_f32, vcltq_f32, vcltzq_s32, vcombine_f32, vcvtq_f32_s32, vcvtq_u32_f32, vdivq_f32,
        vdupq_n_f32, vdupq_n_s32, vdupq_n_u32, vget_high_f32, vgetq_lane_f32, vld1q_f32, vld1q_s32,
        vld1q_u32, vmulq_f32, vreinterpretq_s32_f32, vst1q_f32, vst1q_u32, vsubq_f32, vsubq_s32,
        vzip1q_f32, vzip2q_f32,
    };

    /// Four lanes in a NEON register.
    #[derive(Clone, Copy)]
    pub(crate) struct F4(float32x4_t);

    /// Bit `i` set if lane `i` of the all-ones/all-zeros mask `m` is set (SSE's `movemask`).
    #[inline(always)]
    fn movemask(m: uint32x4_t) -> u32 {
        let weights = [1u32, 2, 4, 8];
        unsafe { vaddvq_u32(vandq_u32(m, vld1q_u32(weights.as_ptr()))) }
    }

    impl F4 {
        #[inline(always)]
        pub(crate) fn new(l: [f32; 4]) -> Self {
            Self(unsafe { vld1q_f32(l.as_ptr()) })
        }
        #[inline(always)]
        pub(crate) fn splat(x: f32) -> Self {
            Self(unsafe { vdupq_n_f32(x) })
        }
        #[inline(always)]
        pub(crate) fn add(self, o: Self) -> Self {
            Self(unsafe { vaddq_f32(self.0, o.0) })
        }
        #[inline(always)]
        pub(crate) fn sub(self, o: Self) -> Self {
            Self(unsafe { vsubq_f32(self.0, o.0) })
        }
        #[inline(always)]
        pub(crate) fn mul(self, o: Self) -> Self {
            Self(unsafe { vmulq_f32(self.0, o.0) })
        }
        #[inline(always)]
        pub(crate) fn div(self, o: Self) -> Self {
            Self(unsafe { vdivq_f32(self.0, o.0) })
        }
        /// The lanes in order.
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 4] {
            let mut out = [0.0f32; 4];
            // SAFETY: see above; the store writes the four `f32` of `out`.
            unsafe { vst1q_f32(out.as_mut_ptr(), self.0) };
            out
        }
        /// Per lane `a.wrapping_sub(b) as f32` (rounded to nearest).
        #[inline(always)]
        pub(crate) fn from_i32_difference(a: &[i32; 4], b: i32) -> Self {
            // SAFETY: see above; the load reads the four `i32` of `a`.
            Self(unsafe { vcvtq_f32_s32(vsubq_s32(vld1q_s32(a.as_ptr()), vdupq_n_s32(b))) })
        }
        /// Per lane `|a|`: the sign bit cleared.
        #[inline(always)]
        pub(crate) fn abs(self) -> Self {
            Self(unsafe { vabsq_f32(self.0) })
        }
        /// Per lane `if a < b { a } else { b }` (the second operand when unordered).
        #[inline(always)]
        pub(crate) fn min(self, o: Self) -> Self {
            Self(unsafe { vbslq_f32(vcltq_f32(self.0, o.0), self.0, o.0) })
        }
        /// Per lane `if a > b { a } else { b }` (the second operand when unordered).
        #[inline(always)]
        pub(crate) fn max(self, o: Self) -> Self {
            Self(unsafe { vbslq_f32(vcgtq_f32(self.0, o.0), self.0, o.0) })
        }
        /// `[a0, b0, a1, b1]`.
        #[inline(always)]
        pub(crate) fn unpack_lo(self, o: Self) -> Self {
            Self(unsafe { vzip1q_f32(self.0, o.0) })
        }
        /// `[a2, b2, a3, b3]`.
        #[inline(always)]
        pub(crate) fn unpack_hi(self, o: Self) -> Self {
            Self(unsafe { vzip2q_f32(self.0, o.0) })
        }
        /// `[a2, a3, a2, a3]`.
        #[inline(always)]
        pub(crate) fn high_half(self) -> Self {
            Self(unsafe { vcombine_f32(vget_high_f32(self.0), vget_high_f32(self.0)) })
        }
        /// `[a1, a2, a0, a1]`.
        #[inline(always)]
        pub(crate) fn yzx(self) -> Self {
            let a = self.to_array();
            Self::new([a[1], a[2], a[0], a[1]])
        }
        /// `[a2, a0, a1, a2]`.
        #[inline(always)]
        pub(crate) fn zxy(self) -> Self {
            let a = self.to_array();
            Self::new([a[2], a[0], a[1], a[2]])
        }
        /// `first` if `take_first`, else `second`, without a branch (a bit select).
        #[inline(always)]
        pub(crate) fn select(take_first: bool, first: Self, second: Self) -> Self {
            let mask = 0u32.wrapping_sub(u32::from(take_first));
            Self(unsafe { vbslq_f32(vdupq_n_u32(mask), first.0, second.0) })
        }
        /// Per lane `(x as i32).clamp(0, top)` for a whole `top` in `0..2^31`: the lane clamped
        /// to `[0, top]` (NaN to 0), then truncated (a floor there; exact up to 2^24).
        #[inline(always)]
        pub(crate) fn clamped_trunc(self, top: f32) -> [u32; 4] {
            let x = self.max(Self::splat(0.0)).min(Self::splat(top));
            let mut out = [0u32; 4];
            unsafe { vst1q_u32(out.as_mut_ptr(), vcvtq_u32_f32(x.0)) };
            out
        }
        /// Bit `i` set if lane `i` of `self <= o` (false when unordered).
        #[inline(always)]
        pub(crate) fn le_mask(self, o: Self) -> u32 {
            movemask(unsafe { vcleq_f32(self.0, o.0) })
        }
        /// Bit `i` set if lane `i`'s sign bit is set.
        #[inline(always)]
        pub(crate) fn sign_mask(self) -> u32 {
            movemask(unsafe { vcltzq_s32(vreinterpretq_s32_f32(self.0)) })
        }
        #[inline(always)]
        pub(crate) fn lane0(self) -> f32 {
            unsafe { vgetq_lane_f32::<0>(self.0) }
        }
        #[inline(always)]
        pub(crate) fn lane1(self) -> f32 {
            unsafe { vgetq_lane_f32::<1>(self.0) }
        }
    }
}

#[cfg(any(
    test,
    not(any(
        target_feature = "sse2",
        all(target_arch = "aarch64", target_feature = "neon")
    ))
))]
mod portable {
    /// Four lanes in an array.
    #[derive(Clone, Copy)]
    pub(crate) struct F4([f32; 4]);

    impl F4 {
        #[inline(always)]
        pub(crate) fn new(l: [f32; 4]) -> Self {
            Self(l)
        }
        #[inline(always)]
        pub(crate) fn splat(x: f32) -> Self {
            Self([x, x, x, x]) // written out: `[x; 4]` became a store loop through memory
        }
        /// Lane by lane (written out: no index, so no bounds check to prove away).
        #[inline(always)]
        fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
            let ([a0, a1, a2, a3], [b0, b1, b2, b3]) = (self.0, o.0);
            Self([f(a0, b0), f(a1, b1), f(a2, b2), f(a3, b3)])
        }
        /// Bit `i` set if `f` holds for lane `i`.
        #[inline(always)]
        fn mask(self, o: Self, f: impl Fn(f32, f32) -> bool) -> u32 {
            let ([a0, a1, a2, a3], [b0, b1, b2, b3]) = (self.0, o.0);
            u32::from(f(a0, b0))
                | u32::from(f(a1, b1)) << 1
                | u32::from(f(a2, b2)) << 2
                | u32::from(f(a3, b3)) << 3
        }
        #[inline(always)]
        pub(crate) fn add(self, o: Self) -> Self {
            self.zip(o, |a, b| a + b)
        }
        #[inline(always)]
        pub(crate) fn sub(self, o: Self) -> Self {
            self.zip(o, |a, b| a - b)
        }
        #[inline(always)]
        pub(crate) fn mul(self, o: Self) -> Self {
            self.zip(o, |a, b| a * b)
        }
        #[inline(always)]
        pub(crate) fn div(self, o: Self) -> Self {
            self.zip(o, |a, b| a / b)
        }
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 4] {
            self.0
        }
        /// Only the vector backends' callers need it (`wide::slab4_fixed`); here for the
        /// comparison test.
        #[cfg(test)]
        #[inline(always)]
        pub(crate) fn from_i32_difference(a: &[i32; 4], b: i32) -> Self {
            Self(a.map(|x| x.wrapping_sub(b) as f32))
        }
        #[inline(always)]
        pub(crate) fn abs(self) -> Self {
            Self(self.0.map(libm::fabsf))
        }
        #[inline(always)]
        pub(crate) fn min(self, o: Self) -> Self {
            self.zip(o, |a, b| if a < b { a } else { b })
        }
        #[inline(always)]
        pub(crate) fn max(self, o: Self) -> Self {
            self.zip(o, |a, b| if a > b { a } else { b })
        }
        #[inline(always)]
        pub(crate) fn unpack_lo(self, o: Self) -> Self {
            let (a, b) = (self.0, o.0);
            Self([a[0], b[0], a[1], b[1]])
        }
        #[inline(always)]
        pub(crate) fn unpack_hi(self, o: Self) -> Self {
            let (a, b) = (self.0, o.0);
            Self([a[2], b[2], a[3], b[3]])
        }
        #[inline(always)]
        pub(crate) fn high_half(self) -> Self {
            let a = self.0;
            Self([a[2], a[3], a[2], a[3]])
        }
        #[inline(always)]
        pub(crate) fn yzx(self) -> Self {
            let a = self.0;
            Self([a[1], a[2], a[0], a[1]])
        }
        #[inline(always)]
        pub(crate) fn zxy(self) -> Self {
            let a = self.0;
            Self([a[2], a[0], a[1], a[2]])
        }
        #[inline(always)]
        pub(crate) fn select(take_first: bool, first: Self, second: Self) -> Self {
            if take_first {
                first
            } else {
                second
            }
        }
        #[inline(always)]
        pub(crate) fn clamped_trunc(self, top: f32) -> [u32; 4] {
            let x = self.max(Self::splat(0.0)).min(Self::splat(top));
            x.0.map(|v| v as u32)
        }
        #[inline(always)]
        pub(crate) fn le_mask(self, o: Self) -> u32 {
            self.mask(o, |a, b| a <= b)
        }
        #[inline(always)]
        pub(crate) fn sign_mask(self) -> u32 {
            self.mask(self, |a, _| a.to_bits() >> 31 != 0)
        }
        #[inline(always)]
        pub(crate) fn lane0(self) -> f32 {
            self.0[0]
        }
        #[inline(always)]
        pub(crate) fn lane1(self) -> f32 {
            self.0[1]
        }
    }
}

#[cfg(all(target_arch = "aarch64", target_feature = "neon"))]
pub(crate) use neon::F4;
#[cfg(not(any(
    target_feature = "sse2",
    all(target_arch = "aarch64", target_feature = "neon")
)))]
pub(crate) use portable::F4;
#[cfg(target_feature = "sse2")]
pub(crate) use sse::F4;

#[cfg(test)]
mod tests {
    use super::F4;

    /// Every operation of the target's vector backend (SSE or NEON) against the portable one,
    /// bit for bit in all four lanes, on lanes drawn from a list of awkward values (NaN,
    /// infinities, signed zeros, subnormals).
    #[cfg(any(
        target_feature = "sse2",
        all(target_arch = "aarch64", target_feature = "neon")
    ))]
    #[test]
    fn vector_and_portable_backends_agree_bit_for_bit() {
        use super::{portable::F4 as P, F4 as S};
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            3.0e38,
            -3.0e38,
            1.0e-45,
            -1.0e-45,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            7.25,
            -2.5,
        ];
        let n = values.len();
        let bits = |l0: f32, l1: f32| [l0.to_bits(), l1.to_bits()];
        let lanes_at = |k: usize| -> [f32; 4] {
            core::array::from_fn(|i| values[(k * 7 + i * 3 + k / n) % n])
        };
        for k in 0..n * n {
            let (a, b) = (lanes_at(k), lanes_at(k * 5 + 1));
            let (pa, pb, sa, sb) = (P::new(a), P::new(b), S::new(a), S::new(b));
            let same = |p: P, s: S, what: &str| {
                assert_eq!(
                    bits(p.lane0(), p.lane1()),
                    bits(s.lane0(), s.lane1()),
                    "{what} {a:?} {b:?}"
                );
                assert_eq!(
                    p.to_array().map(f32::to_bits),
                    s.to_array().map(f32::to_bits),
                    "{what} (all lanes) {a:?} {b:?}"
                );
            };
            same(pa.add(pb), sa.add(sb), "add");
            same(pa.sub(pb), sa.sub(sb), "sub");
            same(pa.mul(pb), sa.mul(sb), "mul");
            same(pa.div(pb), sa.div(sb), "div");
            assert_eq!(
                pa.to_array().map(f32::to_bits),
                sa.to_array().map(f32::to_bits),
                "to_array {a:?}"
            );
            same(pa.abs(), sa.abs(), "abs");
            same(pa.min(pb), sa.min(sb), "min");
            same(pa.max(pb), sa.max(sb), "max");
            same(pa.unpack_lo(pb), sa.unpack_lo(sb), "unpack_lo");
            same(pa.unpack_hi(pb), sa.unpack_hi(sb), "unpack_hi");
            same(pa.high_half(), sa.high_half(), "high_half");
            same(pa.yzx(), sa.yzx(), "yzx");
            same(pa.zxy(), sa.zxy(), "zxy");
            for take_first in [true, false] {
                same(
                    P::select(take_first, pa, pb),
                    S::select(take_first, sa, sb),
                    "select",
                );
            }
            assert_eq!(pa.sign_mask(), sa.sign_mask(), "sign_mask {a:?}");
            same(P::splat(a[0]), S::splat(a[0]), "splat");
            assert_eq!(pa.le_mask(pb), sa.le_mask(sb), "le_mask {a:?} {b:?}");
            // Integer differences that wrap and that round (beyond 2^24) when converted.
            let ints = a.map(|x| x.to_bits() as i32);
            let by = b[0].to_bits() as i32 >> (k % 32);
            same(
                P::from_i32_difference(&ints, by),
                S::from_i32_difference(&ints, by),
                "from_i32_difference",
            );
            for top in [0.0, 3.0, 31.0, 16_777_216.0, 2_147_483_520.0] {
                assert_eq!(
                    pa.clamped_trunc(top),
                    sa.clamped_trunc(top),
                    "clamped_trunc {a:?}"
                );
            }
        }
    }

    fn lanes(v: F4) -> [u32; 2] {
        [v.lane0().to_bits(), v.lane1().to_bits()]
    }

    #[test]
    fn min_and_max_return_the_second_operand_unless_the_first_wins() {
        let nan = f32::NAN;
        let cases = [
            (1.0, 2.0),
            (2.0, 1.0),
            (nan, 1.0),
            (1.0, nan),
            (0.0, -0.0),
            (-0.0, 0.0),
        ];
        for (a, b) in cases {
            let (x, y) = (F4::new([a, b, 0.0, 0.0]), F4::new([b, a, 0.0, 0.0]));
            let want_min = [if a < b { a } else { b }, if b < a { b } else { a }];
            let want_max = [if a > b { a } else { b }, if b > a { b } else { a }];
            assert_eq!(lanes(x.min(y)), want_min.map(f32::to_bits), "min {a} {b}");
            assert_eq!(lanes(x.max(y)), want_max.map(f32::to_bits), "max {a} {b}");
        }
    }

    #[test]
    fn shuffles_and_masks_move_the_documented_lanes() {
        let a = F4::new([1.0, 2.0, 3.0, 4.0]);
        let b = F4::new([5.0, 6.0, 7.0, 8.0]);
        assert_eq!(lanes(a.unpack_lo(b)), [1.0f32, 5.0].map(f32::to_bits));
        assert_eq!(lanes(a.unpack_hi(b)), [3.0f32, 7.0].map(f32::to_bits));
        assert_eq!(lanes(a.high_half()), [3.0f32, 4.0].map(f32::to_bits));
        assert_eq!(a.to_array(), [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(a.yzx().to_array(), [2.0, 3.0, 1.0, 2.0]);
        assert_eq!(a.zxy().to_array(), [3.0, 1.0, 2.0, 3.0]);
        assert_eq!(F4::select(true, a, b).to_array(), [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(F4::select(false, a, b).to_array(), [5.0, 6.0, 7.0, 8.0]);
        let c = F4::new([1.0, 9.0, f32::NAN, 4.0]);
        assert_eq!(a.le_mask(c), 0b1011);
        let sum = b.sub(F4::splat(1.0)).mul(F4::splat(2.0));
        assert_eq!(lanes(sum), [8.0f32, 10.0].map(f32::to_bits));
    }
}
