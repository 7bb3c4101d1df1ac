//! The `f32` slab test of four boxes at once, one box per lane of an [`F4`]: the box test of a
//! 4-wide BVH node (`accel/bvh4`).
//!
//! Each lane performs exactly the operations of `Numerics::slab` for `f32` (`float.rs`) on its
//! box, in the same order: per axis `a = (lo - o_lo) * inv`, `b = (hi - o_hi) * inv`,
//! `near = min(a, b)`, `far = max(a, b)` (SSE semantics: the second operand when unordered);
//! then `t_near = max(near_z, max(near_y, max(near_x, t_min)))`, `t_far` likewise with `min`
//! from `t_max`, and the box is accepted if `t_near <= t_far * widen`. So every lane's
//! decision and entry distance have the bits `slab` gives for that box (tested on random
//! boxes and rays in `kernel/tests/bvh4.rs`).

use super::lanes::F4;

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
        (a.min(b), a.max(b))
    };
    let (near_x, far_x) = axis(0);
    let (near_y, far_y) = axis(1);
    let (near_z, far_z) = axis(2);
    let t_near = near_z.max(near_y.max(near_x.max(F4::splat(t_min))));
    let t_far = far_z.min(far_y.min(far_x.min(F4::splat(t_max))));
    let mask = t_near.le_mask(t_far.mul(F4::splat(widen)));
    (mask, t_near.to_array())
}
