//! The slab test of four boxes at once, one box per lane of an [`F4`]: the box test of a
//! 4-wide BVH node (`accel/bvh4`).
//!
//! `f32` ([`slab4`]): each lane performs exactly the operations of `Numerics::slab` for `f32`
//! (`float.rs`) on its box, in the same order: per axis `a = (lo - o_lo) * inv`,
//! `b = (hi - o_hi) * inv`, `near = min(a, b)`, `far = max(a, b)` (SSE semantics: the second
//! operand when unordered); then `t_near = max(near_z, max(near_y, max(near_x, t_min)))`,
//! `t_far` likewise with `min` from `t_max`, and the box is accepted if
//! `t_near <= t_far * widen`. So every lane's decision and entry distance have the bits `slab`
//! gives for that box (tested on random boxes and rays in `kernel/tests/bvh4.rs`).
//!
//! Fixed point ([`slab4_fixed`], where `F4` has vector lanes): the same steps in `f32` lanes on
//! exact integer plane distances, with relative margins that make the test conservative. Its
//! decisions may differ from the integer `slab` (24 `i128` products per node, the larger part
//! of fixed-point traversal time on a 64-bit host), never its hits.

use super::lanes::F4;

/// Entry and exit of four boxes from each axis's plane distances `(a, b)` (`axis(k)`, `k` in
/// `0..3`): per axis `near = min(a, b)`, `far = max(a, b)`, then
/// `t_near = max(near_z, max(near_y, max(near_x, t_min)))` and `t_far` likewise with `min`
/// from `t_max`. The order is `slab`'s, which decides the NaN cases (SSE `min`/`max` return the
/// second operand when unordered), so both lane tests share it.
#[inline(always)]
fn enter_exit(axis: impl Fn(usize) -> (F4, F4), t_min: f32, t_max: f32) -> (F4, F4) {
    let near_far = |k: usize| {
        let (a, b) = axis(k);
        (a.min(b), a.max(b))
    };
    let (near_x, far_x) = near_far(0);
    let (near_y, far_y) = near_far(1);
    let (near_z, far_z) = near_far(2);
    let t_near = near_z.max(near_y.max(near_x.max(F4::splat(t_min))));
    let t_far = far_z.min(far_y.min(far_x.min(F4::splat(t_max))));
    (t_near, t_far)
}

/// `Numerics::slab4` for `f32`: `o_lo`, `o_hi`, `inv` are the ray's shifted origins and
/// reciprocal direction (lanes x, y, z, z), `widen` the far-end factor; boxes in structure of
/// arrays `lo[axis][box]`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn slab4(
    o_lo: [f32; 4],
    o_hi: [f32; 4],
    inv: [f32; 4],
    widen: f32,
    lo: &[[f32; 4]; 3],
    hi: &[[f32; 4]; 3],
    t_min: f32,
    t_max: f32,
) -> (u32, [f32; 4]) {
    let axis = |k: usize| {
        let k = k.min(2); // a no-op that shows the compiler the bound
        let (l, h) = (F4::new(lo[k]), F4::new(hi[k]));
        let inv = F4::splat(inv[k]);
        let a = l.sub(F4::splat(o_lo[k])).mul(inv);
        let b = h.sub(F4::splat(o_hi[k])).mul(inv);
        // See `slab_pair` in float.rs for the NaN cases (0 * inf): the same per lane here.
        (a, b)
    };
    let (t_near, t_far) = enter_exit(axis, t_min, t_max);
    let mask = t_near.le_mask(t_far.mul(F4::splat(widen)));
    (mask, t_near.to_array())
}

/// [`slab4`] of eight boxes in the 256-bit lanes of AVX (`Numerics::slab8_avx2` for `f32`): each lane performs the operations of
/// one [`slab4`] lane, in its order (`vsubps`, `vmulps`, `vminps`/`vmaxps` with the same operand
/// order, so the same result when unordered, and an ordered `<=`), so every box gets the bits
/// [`slab4`] gives it. Bit `i` of the mask is box `i`.
///
/// # Safety
/// The CPU must have AVX.
#[cfg(target_arch = "x86_64")]
#[allow(clippy::too_many_arguments, unsafe_code)]
#[target_feature(enable = "avx")]
#[inline]
pub(super) unsafe fn slab8_avx2(
    o_lo: [f32; 4],
    o_hi: [f32; 4],
    inv: [f32; 4],
    widen: f32,
    lo: &[[f32; 8]; 3],
    hi: &[[f32; 8]; 3],
    t_min: f32,
    t_max: f32,
) -> (u32, [f32; 8]) {
    use core::arch::x86_64::{
        _mm256_cmp_ps, _mm256_loadu_ps, _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps,
        _mm256_mul_ps, _mm256_set1_ps, _mm256_storeu_ps, _mm256_sub_ps, _CMP_LE_OQ,
    };
    // SAFETY: AVX is present (the caller's guarantee); every load and store is of eight `f32`
    // inside an `[f32; 8]`.
    unsafe {
        let mut t_near = _mm256_set1_ps(t_min);
        let mut t_far = _mm256_set1_ps(t_max);
        for k in 0..3 {
            let k = k.min(2); // a no-op that shows the compiler the bound
            let inv = _mm256_set1_ps(inv[k]);
            let a = _mm256_mul_ps(
                _mm256_sub_ps(_mm256_loadu_ps(lo[k].as_ptr()), _mm256_set1_ps(o_lo[k])),
                inv,
            );
            let b = _mm256_mul_ps(
                _mm256_sub_ps(_mm256_loadu_ps(hi[k].as_ptr()), _mm256_set1_ps(o_hi[k])),
                inv,
            );
            // `enter_exit`'s folds: `near.max(acc)`, `far.min(acc)`, x first.
            t_near = _mm256_max_ps(_mm256_min_ps(a, b), t_near);
            t_far = _mm256_min_ps(_mm256_max_ps(a, b), t_far);
        }
        let inside =
            _mm256_cmp_ps::<_CMP_LE_OQ>(t_near, _mm256_mul_ps(t_far, _mm256_set1_ps(widen)));
        let mut t = [0.0f32; 8];
        _mm256_storeu_ps(t.as_mut_ptr(), t_near);
        (_mm256_movemask_ps(inside) as u32, t)
    }
}

/// [`slab4_fixed`] of eight boxes in the 256-bit lanes of AVX2 (`Numerics::slab8_avx2` for
/// fixed point): each lane performs the operations of one [`slab4_fixed`] lane in their order
/// (wrapping `i32` difference, conversion to `f32`, the products, `min`/`max` with the same
/// operand order, the two scalings, the ordered `<=`, the clamp and the truncation), so every
/// box gets the bits [`slab4_fixed`] gives it. Bit `i` of the mask is box `i`.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[allow(clippy::too_many_arguments, unsafe_code)]
#[target_feature(enable = "avx,avx2")]
#[inline]
pub(super) unsafe fn slab8_avx2_fixed(
    o_lo: [i32; 3],
    o_hi: [i32; 3],
    inv: [f32; 3],
    lo: &[[i32; 8]; 3],
    hi: &[[i32; 8]; 3],
    t_min: i32,
    t_max: i32,
) -> (u32, [i32; 8]) {
    use core::arch::x86_64::{
        __m256i, _mm256_cmp_ps, _mm256_cvtepi32_ps, _mm256_cvttps_epi32, _mm256_loadu_si256,
        _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_set1_epi32,
        _mm256_set1_ps, _mm256_storeu_si256, _mm256_sub_epi32, _CMP_LE_OQ,
    };
    // SAFETY: AVX2 is present (the caller's guarantee); every load and store is of eight
    // `i32` inside an `[i32; 8]`.
    unsafe {
        let difference = |planes: &[i32; 8], o: i32| {
            let p = _mm256_loadu_si256(planes.as_ptr().cast::<__m256i>());
            _mm256_cvtepi32_ps(_mm256_sub_epi32(p, _mm256_set1_epi32(o)))
        };
        let mut t_near = _mm256_set1_ps(t_min as f32);
        let mut t_far = _mm256_set1_ps(t_max as f32 + 2.0);
        for k in 0..3 {
            let k = k.min(2); // a no-op that shows the compiler the bound
            let inv = _mm256_set1_ps(inv[k]);
            let a = _mm256_mul_ps(difference(&lo[k], o_lo[k]), inv);
            let b = _mm256_mul_ps(difference(&hi[k], o_hi[k]), inv);
            // `enter_exit`'s folds: `near.max(acc)`, `far.min(acc)`, x first.
            t_near = _mm256_max_ps(_mm256_min_ps(a, b), t_near);
            t_far = _mm256_min_ps(_mm256_max_ps(a, b), t_far);
        }
        let t_near = _mm256_mul_ps(t_near, _mm256_set1_ps(FIXED_SHRINK));
        let grown = _mm256_mul_ps(t_far, _mm256_set1_ps(FIXED_GROW));
        let inside = _mm256_cmp_ps::<_CMP_LE_OQ>(t_near, grown);
        // `clamped_trunc`: `max(x, 0)`, then `min(.., top)`, then truncation.
        let clamped = _mm256_min_ps(
            _mm256_max_ps(t_near, _mm256_set1_ps(0.0)),
            _mm256_set1_ps(FIXED_ENTRY_TOP),
        );
        let mut t = [0i32; 8];
        _mm256_storeu_si256(
            t.as_mut_ptr().cast::<__m256i>(),
            _mm256_cvttps_epi32(clamped),
        );
        (_mm256_movemask_ps(inside) as u32, t)
    }
}

/// [`slab4_fixed`]'s scaling of the entry (`1 - 2^-20`).
#[cfg(any(
    target_feature = "sse2",
    all(target_arch = "aarch64", target_feature = "neon")
))]
const FIXED_SHRINK: f32 = 1.0 - 1.0 / 1_048_576.0;
/// [`slab4_fixed`]'s scaling of the exit (`1 + 2^-20`).
#[cfg(any(
    target_feature = "sse2",
    all(target_arch = "aarch64", target_feature = "neon")
))]
const FIXED_GROW: f32 = 1.0 + 1.0 / 1_048_576.0;
/// The largest `f32` below 2^31: [`slab4_fixed`] clamps entries to it before conversion to raw
/// `i32`.
#[cfg(any(
    target_feature = "sse2",
    all(target_arch = "aarch64", target_feature = "neon")
))]
const FIXED_ENTRY_TOP: f32 = 2_147_483_520.0;

/// `Numerics::slab4` for fixed point where [`F4`] has vector lanes: the four boxes' raw Q16.16
/// planes against the ray's shifted raw origins `o_lo`, `o_hi` (see `FixedRay`), with `inv`
/// the reciprocal direction `2^30 / dir` rounded to `f32`; distances in raw Q16.16 units.
///
/// Conservative, not equal to `slab`: per lane and axis the plane distance is an exact `i32`
/// difference, rounded once to `f32`, times `inv` (rounded twice), so each of `a`, `b` is
/// within a relative `4·2^-24` of the exact `(plane − o)·2^30 / dir`, with its sign. The entry
/// `max(t_min, near…)` is scaled down by `1 − 2^-20` and the exit `min(t_max + 2, far…)` up by
/// `1 + 2^-20`, which outweighs those errors and the rounding of the scaling itself (the shifted
/// origins and the `+ 2` only add slack): whenever the ray meets the box at an exact `t` in
/// `[t_min, t_max + 1]`, the box is accepted and its entry is at most `t`. A hit's distance is
/// its exact one rounded down, so no box holding a hit up to `t_max` (the best hit so far) is
/// culled, and none is popped too late: its entry is at most the hit's exact `t`, less than the
/// reported one plus one. Negative ends keep their sign under the scalings. A zero direction
/// component gives infinite plane distances, and `0·inf = NaN` (an origin one raw unit outside
/// a face) resolves by the `min`/`max` operand order as in the `f32` test, never to a miss of
/// a box the ray meets. Rejected lanes' entries are unspecified.
///
/// Decisions and entries may differ from `slab`'s integer test (which pads by two raw units
/// instead); hits do not, as the differential tests check. Targets without vector lanes use
/// `slab` per box.
#[allow(clippy::too_many_arguments)]
#[cfg(any(
    target_feature = "sse2",
    all(target_arch = "aarch64", target_feature = "neon")
))]
#[inline(always)]
pub(super) fn slab4_fixed(
    o_lo: [i32; 3],
    o_hi: [i32; 3],
    inv: [f32; 3],
    lo: &[[i32; 4]; 3],
    hi: &[[i32; 4]; 3],
    t_min: i32,
    t_max: i32,
) -> (u32, [i32; 4]) {
    let axis = |k: usize| {
        let k = k.min(2); // a no-op that shows the compiler the bound
        let inv = F4::splat(inv[k]);
        // Unused slots (inverted boxes at the range ends) may wrap here: masked by the caller.
        let a = F4::from_i32_difference(&lo[k], o_lo[k]).mul(inv);
        let b = F4::from_i32_difference(&hi[k], o_hi[k]).mul(inv);
        (a, b)
    };
    let (t_near, t_far) = enter_exit(axis, t_min as f32, t_max as f32 + 2.0);
    let t_near = t_near.mul(F4::splat(FIXED_SHRINK));
    let mask = t_near.le_mask(t_far.mul(F4::splat(FIXED_GROW)));
    // Accepted entries lie in [0, 2^31]: truncation is a floor there.
    let t = t_near.clamped_trunc(FIXED_ENTRY_TOP);
    (mask, t.map(|x| x as i32))
}
