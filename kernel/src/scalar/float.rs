//! `f32` mode: conservative slab test (Ize 2013) and watertight ray/triangle test
//! (Woop, Benthin, Wald 2013, "Watertight Ray/Triangle Intersection", JCGT 2(1)).
//!
//! Rounding rules: only `+ - * /` and [`sqrtf`] (correctly rounded everywhere), no fused
//! multiply-add, min/max as explicit comparisons. Every function is a pure function of its
//! inputs, so a primitive gives the same bits whichever accelerator asks. No `f64` on any path
//! of this mode on bare-metal targets (the exact parts use error-free `f32` transformations,
//! `float/eft.rs`), so a core with a single-precision FPU links no soft-float; hosted targets
//! may shortcut the exact distance through `f64` where a certificate shows the same bits
//! (`float/rounded.rs`); `unit_dir_f64` serves fixed point only.

mod eft;
#[cfg(not(target_os = "none"))]
mod rounded;
mod sqrt;

pub(crate) use sqrt::{sqrt, sqrtf};

use super::lanes::F4;
use super::sealed::Numerics;
use super::Scalar;
use crate::error::{PointError, RayError};
use eft::{exact_cross_sum, recip_binade, scale_to_2_60, Df};

/// Largest coordinate magnitude accepted in `f32` mode (2^40, about 1.1e12). Beyond it the
/// triple products of the triangle test could overflow to infinity and silently lose hits.
pub const F32_COORD_LIMIT: f32 = 1_099_511_627_776.0;

/// Relative margin of the slab test and of node padding (2^-19). It covers the rounding of the
/// slab arithmetic (Ize's 1 + 2γ₃ is about 3.6e-7) and the lateral rounding of the triangle
/// test's shear (a few ulps of the largest coordinate), with room to spare.
///
/// The direction's length does not enter these bounds: the slab test (through `1 / dir`), the
/// triangle test (through its shear) and the hit point check (`origin + t·dir`) all measure
/// `t` along the same stored `f32` direction, so a hit and the boxes around it are compared in
/// one parametrisation whatever `|dir|` is. The normalisation error (see [`normalized`]) only
/// makes `t` a distance to within a relative 2^-22.
const MARGIN: f32 = 1.0 / 524_288.0;
/// The factor of `Numerics::widen`: exits up to `(1 + 2·MARGIN)·t` count as inside.
const WIDEN: f32 = 1.0 + 2.0 * MARGIN;

/// Per-ray data for `f32` mode. Built only by [`crate::Ray`]'s constructors.
#[derive(Clone, Copy, Debug)]
pub struct FloatRay {
    /// Origin, z repeated in lane 3 (stored and read as one vector, see [`lanes`]).
    origin: [f32; 4],
    /// Unit direction, z repeated in lane 3.
    dir: [f32; 4],
    /// `1 / dir`, `±inf` for `±0` components (sign preserved, never NaN); z repeated in lane 3.
    inv: [f32; 4],
    /// Origin as seen from the boxes' `lo` planes: moved up by the margin, which enlarges
    /// every box downwards, so near distances are never overestimated nor far ones
    /// underestimated.
    o_lo: [f32; 4],
    /// Origin as seen from the boxes' `hi` planes: moved down by the margin.
    o_hi: [f32; 4],
    /// Watertight test: axis permutation (kx, ky, kz).
    k: [Axis; 3],
    /// Watertight test: shear constants Sx, Sy, Sz.
    shear: [f32; 3],
    /// The origin permuted to (kx, ky, kz).
    o_perm: [f32; 3],
}

/// A coordinate axis. As an index it is below 3 by its type, so indexing a 3-vector with it
/// needs no bounds check. (A word wide, as every other field of [`FloatRay`].)
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
enum Axis {
    X = 0,
    Y = 1,
    Z = 2,
}

impl Axis {
    /// The axis of index `i` (0, 1, 2; anything else is z).
    #[inline(always)]
    fn from_index(i: u32) -> Axis {
        const AXES: [Axis; 4] = [Axis::X, Axis::Y, Axis::Z, Axis::Z];
        AXES[(i & 3) as usize]
    }
}

/// `v[k]`.
#[inline(always)]
fn axis(v: &[f32; 3], k: Axis) -> f32 {
    v[k as usize]
}

/// `v[k]` of a vector in lanes. Hosted targets pick the lane by selects, with neither a branch
/// (a ray's axes follow its direction, which the predictor cannot guess) nor a lane read back
/// from memory; bare-metal targets index (less flash).
#[inline(always)]
fn lane(v: &[f32; 4], k: Axis) -> f32 {
    if cfg!(target_os = "none") {
        return v[k as usize];
    }
    let [x, y, z, _] = v.map(f32::to_bits);
    let x_or_y = select_bits(k == Axis::X, x, y);
    f32::from_bits(select_bits(k == Axis::Z, z, x_or_y))
}

/// The watertight test's axes `[kx, ky, kz]` for a ray along `dir` (lanes x, y, z, z): `kz`
/// the dominant axis (the first of equal magnitudes), `kx`, `ky` the two others in cyclic
/// order, swapped if `dir[kz] < 0` so that the winding is kept (`dir[kz]` is never zero for a
/// non-zero direction, so its sign bit decides). Found by integer operations on lane masks,
/// without branches (incoherent rays' axes are not predictable).
#[inline(always)]
fn shear_axes(dir: F4) -> [Axis; 3] {
    let a = dir.abs();
    // Bit i: |dir_i| >= |dir_(i+1)|, and |dir_i| >= |dir_(i+2)| (indices mod 3).
    let (ge_next, ge_after) = (a.yzx().le_mask(a), a.zxy().le_mask(a));
    let x_dominant = ge_next & ge_after & 1;
    let y_over_z = (ge_next >> 1) & 1;
    // 0 if x dominates, else 1 for y (|y| >= |z|) or 2 for z.
    let kz = (1 - x_dominant) * (2 - y_over_z);
    let negative = (dir.sign_mask() >> kz) & 1;
    // The axes after kz: kz + 1 and kz + 2 (mod 3), two bits each, read from one constant.
    const AFTER: u32 = 0b00_10_01 | 0b01_00_10 << 8;
    let (kx, ky) = ((AFTER >> (2 * kz)) & 3, (AFTER >> (8 + 2 * kz)) & 3);
    let swap = (kx ^ ky) & 0u32.wrapping_sub(negative);
    [kx ^ swap, ky ^ swap, kz].map(Axis::from_index)
}

/// `if take_first { first } else { second }` as bit operations, which compilers turn into a
/// conditional move where a plain `if` may become a branch.
#[inline(always)]
fn select_bits(take_first: bool, first: u32, second: u32) -> u32 {
    let mask = 0u32.wrapping_sub(u32::from(take_first));
    (first & mask) | (second & !mask)
}

/// `[x, y, z, z]`: a 3-vector as the four lanes of an [`F4`].
#[inline(always)]
fn lanes([x, y, z]: [f32; 3]) -> [f32; 4] {
    [x, y, z, z]
}

/// [`lanes`] of `p` in an [`F4`].
#[inline(always)]
fn vector(p: &[f32; 3]) -> F4 {
    F4::new(lanes(*p))
}

fn abs(x: f32) -> f32 {
    libm::fabsf(x)
}

/// The largest `|x|` of `values`, `0` for none (NaN-free inputs, as every caller's are).
/// Inlined on hosted targets (speed); bare-metal targets keep one copy (flash).
#[cfg_attr(not(target_os = "none"), inline(always))]
#[cfg_attr(target_os = "none", inline(never))]
fn max_abs(values: &[f32]) -> f32 {
    values.iter().fold(0.0, |m, &x| m.max_of(abs(x)))
}

/// How far the margin moves a coordinate of a point or box whose largest magnitude is `m`:
/// `max(m·MARGIN, TINY)` (the smallest subnormal).
///
/// `x ± margin_offset(m)` for `|x| <= m` is `x` moved by `m·MARGIN`, and by at least one ulp:
/// a non-zero `m·MARGIN` is at least 16 ulps of `x`, so the sum never rounds back to `x`; a
/// zero one means `x` is zero or subnormal, whose neighbours are `x ± TINY` exactly. (A test
/// checks this against stepping the bits; only the sign of a zero result can differ, which no
/// comparison sees.) Plain arithmetic, so whole vectors of coordinates move at once.
#[inline(always)]
fn margin_offset(m: f32) -> f32 {
    const TINY: f32 = f32::from_bits(1);
    let delta = m * MARGIN;
    if delta > TINY {
        delta
    } else {
        TINY
    }
}

fn check_coord(x: f32) -> Result<(), PointError> {
    // One comparison on the common path: it fails for NaN and infinities too.
    if abs(x) <= F32_COORD_LIMIT {
        Ok(())
    } else if x.is_finite() {
        Err(PointError::OutOfRange {
            limit: F32_COORD_LIMIT,
        })
    } else {
        Err(PointError::NonFinite)
    }
}

/// The float just below 1, `1 - 2^-24`: its correctly rounded square root is itself.
const BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;

/// Unit vector along `d` in `f32` and its reciprocal `1 / dir` (lane-wise IEEE quotients), z
/// repeated in lane 3: [`normalized`]`(d)`, bit for bit, but found by one division, without
/// the scaling and the square root, when `d` is a unit vector as [`normalized`] sees it or one
/// ulp of length short of one (most unit vectors a caller rounds to `f32`).
///
/// That is when `q = (dx·dx + dy·dy) + dz·dz`, in `f32`, is 1 or its upper neighbour
/// `1 + 2^-23`: then [`normalized`] returns `d` itself. It scales `d` by a power of two `k`,
/// and the squared length of `k·d` it computes is `k²·q` (scaling by a power of two commutes
/// with rounding; a square small enough to round differently once scaled lies far below half
/// an ulp of a sum near 1 and vanishes in it either way), so the length is `k·sqrtf(q) = k`
/// (the square root of `1 + 2^-23` lies just under the midpoint `1 + 2^-24` and rounds to 1),
/// and each quotient `(k·d_i) / k` is `d_i`. When `q` is the float below 1, `1 - 2^-24` (also
/// common among rounded unit vectors), the length is likewise `k·sqrtf(q) = k·q` (the square
/// root lies just under the midpoint `1 - 2^-25` and rounds to `q`), so the quotients are
/// `d_i / q`. Which of the two a ray is in is not predictable, so hosted targets compute both
/// (and both reciprocals, so that the traversal's first box test need not wait for `q`) and
/// choose without a branch; bare-metal cores, which pay little for a branch but much for a
/// division, branch. Non-finite components make `q` non-finite and go to [`normalized`],
/// which rejects them.
#[cfg_attr(not(target_os = "none"), inline(always))]
fn unit_dir_and_inverse(d: [f32; 3]) -> Result<(F4, F4), RayError> {
    let one = F4::splat(1.0);
    let q = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    // `q` is `BELOW_ONE`, 1 or the next float up (consecutive bits): one unsigned comparison.
    let above_below_one = q.to_bits().wrapping_sub(BELOW_ONE.to_bits());
    if above_below_one > 2 {
        let unit = F4::new(normalized(d)?);
        return Ok((unit, one.div(unit)));
    }
    let below = above_below_one == 0;
    let given = vector(&d);
    let shortened = given.div(F4::splat(BELOW_ONE));
    if cfg!(target_os = "none") {
        let unit = if below { shortened } else { given };
        return Ok((unit, one.div(unit)));
    }
    Ok((
        F4::select(below, shortened, given),
        F4::select(below, one.div(shortened), one.div(given)),
    ))
}

/// Unit vector along `d` in `f32`, z repeated in lane 3: `d` scaled by the power of two that
/// brings its largest component into `[1, 2)` (exact, except for components below 2^-149 of
/// that one, whose unit values are subnormal anyway), then divided by the correctly rounded
/// length. Neither overflow nor underflow can occur in the squares (their sum lies in
/// `[1, 12)`).
///
/// Error: the squared length carries at most three roundings (`γ₃ ≤ 3·2^-24`), its square
/// root halves that and adds one, each quotient one more, so every component is within
/// `3.5·2^-24` relative of the exact unit vector's, `| |dir| - 1 | < 2^-22`, and
/// `|dir_i| <= 1 + 2^-23`.
#[cfg_attr(not(target_os = "none"), inline(always))]
fn normalized(d: [f32; 3]) -> Result<[f32; 4], RayError> {
    if !(d[0].is_finite() && d[1].is_finite() && d[2].is_finite()) {
        return Err(RayError::NonFiniteDirection);
    }
    let m = max_abs(&d);
    if m == 0.0 {
        return Err(RayError::ZeroDirection);
    }
    let k = recip_binade(m);
    let s = [d[0] * k, d[1] * k, d[2] * k];
    let len = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    // Three quotients in one vector division (each lane the same IEEE quotient), z repeated.
    Ok(vector(&s).div(F4::splat(len)).to_array())
}

/// Unit vector along `d`, computed in `f64` after scaling by the largest component so that
/// neither overflow nor underflow can occur (fixed point's directions, which keep 30 bits).
pub(super) fn unit_dir_f64(d: [f64; 3]) -> Result<[f64; 3], RayError> {
    if !(d[0].is_finite() && d[1].is_finite() && d[2].is_finite()) {
        return Err(RayError::NonFiniteDirection);
    }
    let m = libm::fmax(
        libm::fabs(d[0]),
        libm::fmax(libm::fabs(d[1]), libm::fabs(d[2])),
    );
    if m == 0.0 {
        return Err(RayError::ZeroDirection);
    }
    let inv_m = 1.0 / m;
    let s = [d[0] * inv_m, d[1] * inv_m, d[2] * inv_m];
    let inv_len = 1.0 / sqrt::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    Ok([s[0] * inv_len, s[1] * inv_len, s[2] * inv_len])
}

/// [`unit_dir_f64`] of an `f32` direction (every `f32` is exact in `f64`), for fixed point.
///
/// Each component is within a relative `6.5·2^-53` of the exact `d_i / |d|` (to first order):
/// the scaling by `1/m` rounds once in common (which the normalisation cancels) and once per
/// component (`2^-53`, and as much in `|d|`); the sum of squares `3·2^-53`, the square root
/// half of that plus its own rounding, the reciprocal and the product one rounding each.
#[cfg_attr(not(target_os = "none"), inline(always))]
pub(super) fn unit_dir_from_f32(d: [f32; 3]) -> Result<[f64; 3], RayError> {
    unit_dir_f64(d.map(f64::from))
}

/// `d / |d|` in `f64` without [`unit_dir_f64`]'s scaling and reciprocals: `None` unless `d` is
/// finite and not zero. Each component is within a relative `3·2^-53` of the exact `d_i / |d|`
/// (to first order): the squares of `f32` values are exact in `f64`, in range and, but for
/// zero, normal, so the sum rounds twice, the square root once more (and halves the sum's
/// error), the quotient once.
#[cfg_attr(not(target_os = "none"), inline(always))]
pub(super) fn unit_dir_direct_f32(d: [f32; 3]) -> Option<[f64; 3]> {
    let w = d.map(f64::from);
    let q = (w[0] * w[0] + w[1] * w[1]) + w[2] * w[2];
    // False for a zero, infinite or NaN sum.
    if !(q > 0.0 && q < f64::INFINITY) {
        return None;
    }
    let len = sqrt::sqrt(q);
    Some(w.map(|x| x / len))
}

impl FloatRay {
    /// Inlined into the ray constructors: see `ray_data` in the `Scalar` impl below.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn new(origin: [f32; 3], dir: [f32; 3]) -> Result<Self, RayError> {
        for &x in &origin {
            check_coord(x).map_err(RayError::Origin)?;
        }
        let (o_lo, o_hi) = Self::shifted_origins(origin);
        Self::along(origin, o_lo, o_hi, dir)
    }

    /// The ray from a checked origin (with its shifted copies) along `dir`: everything that
    /// depends on the direction. Inlined as [`FloatRay::new`] is.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn along(
        origin: [f32; 3],
        o_lo: [f32; 4],
        o_hi: [f32; 4],
        dir: [f32; 3],
    ) -> Result<Self, RayError> {
        let (dir, inv) = unit_dir_and_inverse(dir)?;
        let [kx, ky, kz] = shear_axes(dir);
        let (dir, inv) = (dir.to_array(), inv.to_array());
        let sz = lane(&inv, kz); // 1 / dir[kz], the same quotient
        let shear = [lane(&dir, kx) * sz, lane(&dir, ky) * sz, sz];
        let origin = lanes(origin);
        Ok(Self {
            origin,
            dir,
            inv,
            o_lo,
            o_hi,
            k: [kx, ky, kz],
            shear,
            o_perm: [lane(&origin, kx), lane(&origin, ky), lane(&origin, kz)],
        })
    }

    /// [`FloatRay::new`] written into `self` field by field, unchanged on error (every check
    /// comes first). The fields are stored one by one from the inlined constructor's values, so
    /// the ray is never assembled elsewhere and moved: a caller that reuses one ray for many
    /// queries does not read back a struct made of narrower stores, which stalls on store
    /// forwarding.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn set(&mut self, origin: [f32; 3], dir: [f32; 3]) -> Result<(), RayError> {
        let Self {
            origin,
            dir,
            inv,
            o_lo,
            o_hi,
            k,
            shear,
            o_perm,
        } = Self::new(origin, dir)?;
        self.origin = origin;
        self.dir = dir;
        self.inv = inv;
        self.o_lo = o_lo;
        self.o_hi = o_hi;
        self.k = k;
        self.shear = shear;
        self.o_perm = o_perm;
        Ok(())
    }

    /// The origins the slab test sees (see the fields' docs), z repeated in lane 3, each
    /// coordinate moved by [`margin_offset`]. Built and stored as whole vectors: read back by
    /// the slab test, lane-wise stores stalled on store forwarding.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn shifted_origins(origin: [f32; 3]) -> ([f32; 4], [f32; 4]) {
        let d = margin_offset(max_abs(&origin));
        let [x, y, z] = origin;
        // Seen from shifted origins the box grows by `d` on each side, whichever plane is
        // near: `lo - (o + d)` and `hi - (o - d)`. For a zero component an origin inside
        // the slab then sees `-inf` and `+inf`, never `0 * inf`.
        ([x + d, y + d, z + d, z + d], [x - d, y - d, z - d, z - d])
    }

    fn moved(&self, origin: [f32; 3]) -> Result<Self, RayError> {
        for &x in &origin {
            check_coord(x).map_err(RayError::Origin)?;
        }
        let (o_lo, o_hi) = Self::shifted_origins(origin);
        let [kx, ky, kz] = self.k;
        Ok(Self {
            origin: lanes(origin),
            o_lo,
            o_hi,
            o_perm: [axis(&origin, kx), axis(&origin, ky), axis(&origin, kz)],
            ..*self
        })
    }

    /// Vertex relative to the origin, permuted to (kx, ky, kz): `v[k] - origin[k]`, the
    /// same IEEE subtraction whichever order it is done in.
    ///
    /// The vertex is read in permuted order straight from memory. (Permuting it after the
    /// subtraction, with the vector in registers, went through a store and reload that
    /// stalled the triangle test.)
    #[inline(always)]
    fn rel_permuted(&self, v: &[f32; 3]) -> [f32; 3] {
        [
            axis(v, self.k[0]) - self.o_perm[0],
            axis(v, self.k[1]) - self.o_perm[1],
            axis(v, self.k[2]) - self.o_perm[2],
        ]
    }

    /// Sheared 2D coordinates and scaled z of a vertex: the ray becomes the +z axis.
    #[inline(always)]
    fn shear(&self, v: &[f32; 3]) -> [f32; 3] {
        let [px, py, pz] = self.rel_permuted(v);
        let [sx, sy, sz] = self.shear;
        [px - sx * pz, py - sy * pz, sz * pz]
    }

    /// The three vertices of a triangle sheared ([`FloatRay::shear`]). Inlined into the
    /// triangle test on hosted targets (speed); bare-metal targets keep one copy for the test
    /// and the barycentrics (flash).
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline(never))]
    fn sheared(&self, v: &[[f32; 3]; 3]) -> [[f32; 3]; 3] {
        [self.shear(&v[0]), self.shear(&v[1]), self.shear(&v[2])]
    }

    /// True if the point at `t` lies in the triangle's box grown by half the traversal margin.
    ///
    /// A hit the watertight test reports on a well-conditioned triangle always passes. One on a
    /// nearly edge-on sliver can carry a `t` far off (det is tiny); rejecting it keeps every
    /// reported hit inside the boxes traversal tests, so no accelerator can cull a hit that
    /// brute force would report.
    ///
    /// Hosted targets test the three axes at once in [`F4`] lanes x, y, z, z, each lane with
    /// the operations of [`FloatRay::point_near_box_per_axis`] (`max` of magnitudes, never NaN,
    /// is exact in any order); bare-metal targets run that per-axis loop (flash).
    #[inline(always)]
    fn point_near_box(&self, t: f32, v: &[[f32; 3]; 3]) -> bool {
        if cfg!(target_os = "none") {
            return self.point_near_box_per_axis(t, v);
        }
        let (a, b, c) = (vector(&v[0]), vector(&v[1]), vector(&v[2]));
        let o = F4::new(self.origin);
        let m = a.abs().max(b.abs()).max(c.abs().max(o.abs()));
        let m = m.max(m.high_half());
        let e = F4::splat(m.lane0().max_of(m.lane1()) * (MARGIN * 0.5));
        let p = o.add(F4::splat(t).mul(F4::new(self.dir)));
        let lo = a.min(b).min(c).sub(e);
        let hi = a.max(b).max(c).add(e);
        lo.le_mask(p) & p.le_mask(hi) == 0b1111
    }

    /// [`FloatRay::point_near_box`], one axis after the other.
    #[inline(always)]
    fn point_near_box_per_axis(&self, t: f32, v: &[[f32; 3]; 3]) -> bool {
        let m = max_abs(&self.origin).max_of(max_abs(v.as_flattened()));
        let e = m * (MARGIN * 0.5);
        let [a, b, c] = v;
        (0..3).all(|i| {
            let i = i.min(2); // a no-op that shows the compiler the bound
            let p = self.origin[i] + t * self.dir[i];
            let lo = a[i].min_of(b[i]).min_of(c[i]);
            let hi = a[i].max_of(b[i]).max_of(c[i]);
            p >= lo - e && p <= hi + e
        })
    }

    /// Edge functions (U, V, W) of the sheared vertices, their sum `det`, and the scaled
    /// distance `num = U·az + V·bz + W·cz`, in double-`f32` (`float/eft.rs`): `t = num / det`.
    ///
    /// The products of the edge functions are taken exactly, so U, V and W keep about 44 bits
    /// however thin the triangle looks from the ray. For a candidate they share one sign, so
    /// `det` loses nothing to cancellation. Two exact power-of-two scalings keep everything in
    /// range without changing `t`, which is invariant under both: x and y are brought up to
    /// the binade 2^60 ([`scale_to_2_60`], so the exact products do not underflow), and U, V,
    /// W by `det`'s binade so that `det` lies in the binade 2^60 (so `num` cannot overflow, nor
    /// small weights underflow). `None` if `det` is zero.
    ///
    /// Inlined on hosted targets (speed); bare-metal targets keep one copy for the distance
    /// and the barycentrics (flash).
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline(never))]
    fn scaled(a: &[f32; 3], b: &[f32; 3], c: &[f32; 3]) -> Option<([Df; 3], Df, Df)> {
        let m = max_abs(&[a[0], a[1], b[0], b[1], c[0], c[1]]);
        if m == 0.0 {
            return None; // every vertex on the ray's line
        }
        let (k1, k2) = scale_to_2_60(m);
        let xy = |p: &[f32; 3]| [p[0] * k1 * k2, p[1] * k1 * k2];
        let (a2, b2, c2) = (xy(a), xy(b), xy(c));
        let e = |p: &[f32; 2], q: &[f32; 2]| Df::diff_of_products(p[0], q[1], p[1], q[0]);
        let (u, v, w) = (e(&c2, &b2), e(&a2, &c2), e(&b2, &a2));
        let det = u.add(v).add(w);
        if det.hi == 0.0 {
            return None;
        }
        // det to the binade 2^60: the weights U/det, V/det, W/det of a hit near a vertex can
        // be far below 1 and still matter (times a large z), so they must stay normal.
        const P60: f32 = 1_152_921_504_606_846_976.0; // 2^60
        const P67: f32 = 147_573_952_589_676_412_928.0; // 2^67
        let r = recip_binade(det.hi);
        let (s1, s2) = if r <= P67 { (r * P60, 1.0) } else { (P60, r) };
        let sc = |x: Df| x.scaled(s1).scaled(s2);
        let (u, v, w, det) = (sc(u), sc(v), sc(w), sc(det));
        let num = u.mul_f32(a[2]).add(v.mul_f32(b[2])).add(w.mul_f32(c[2]));
        Some(([u, v, w], det, num))
    }

    /// Distance and barycentrics (of the second and third vertex) from the sheared vertices,
    /// by [`FloatRay::scaled`]. `None` if the determinant is zero there.
    #[inline(always)]
    fn solve(a: &[f32; 3], b: &[f32; 3], c: &[f32; 3]) -> Option<(f32, f32, f32)> {
        let ([_, v, w], det, num) = Self::scaled(a, b, c)?;
        Some((num.div(det), v.div(det), w.div(det)))
    }

    /// The distance of [`FloatRay::solve`] alone: the rare path of every triangle test, kept
    /// out of the traversal loops on hosted targets (speed), which first try the same `f32`
    /// through `f64` ([`rounded::certified_t`]); bare-metal targets leave inlining to the
    /// optimiser (flash).
    #[cfg_attr(not(target_os = "none"), inline(never))]
    fn candidate_t(a: &[f32; 3], b: &[f32; 3], c: &[f32; 3]) -> Option<f32> {
        #[cfg(not(target_os = "none"))]
        if let Some(t) = rounded::certified_t(a, b, c) {
            return Some(t);
        }
        Self::solved_t(a, b, c)
    }

    /// The distance of [`FloatRay::solve`] alone, always by the double-`f32` solve.
    #[inline(always)]
    fn solved_t(a: &[f32; 3], b: &[f32; 3], c: &[f32; 3]) -> Option<f32> {
        let (_, det, num) = Self::scaled(a, b, c)?;
        Some(num.div(det))
    }

    /// The three edge functions (U, V, W) of the sheared triangle, recomputed with their exact
    /// signs when any is zero ([`exact_edge`]).
    #[inline(always)]
    fn edges(a: &[f32; 3], b: &[f32; 3], c: &[f32; 3]) -> [f32; 3] {
        let u = c[0] * b[1] - c[1] * b[0];
        let v = a[0] * c[1] - a[1] * c[0];
        let w = b[0] * a[1] - b[1] * a[0];
        if (u == 0.0) | (v == 0.0) | (w == 0.0) {
            return [exact_edge(c, b), exact_edge(a, c), exact_edge(b, a)];
        }
        [u, v, w]
    }
}

/// `p0·q1 - p1·q0` as a value with its exact sign, zero exactly when it is zero
/// ([`exact_cross`] with a zero third point). Swapping `p` and `q` negates the result exactly,
/// so a shared edge is seen with opposite signs from its two triangles (watertightness).
#[inline(never)]
fn exact_edge(p: &[f32; 3], q: &[f32; 3]) -> f32 {
    exact_cross(&[*p, *q, [0.0; 3]], Axis::X, Axis::Y)
}

/// The components of `(b - a) × (c - a)` as `(i, j)` axis pairs: x, y, z.
const COMPONENTS: [(Axis, Axis); 3] = [(Axis::Y, Axis::Z), (Axis::Z, Axis::X), (Axis::X, Axis::Y)];

/// True if the triangle has exactly zero area: `(b - a) × (c - a) = 0`. Each component is
/// first evaluated in `f32` ([`surely_non_zero`]); only if none is surely non-zero are they
/// decided exactly ([`exact_cross`]).
#[inline(always)]
fn zero_area(v: &[[f32; 3]; 3]) -> bool {
    !some_component_surely_non_zero(v)
        && COMPONENTS.iter().all(|&(i, j)| exact_cross(v, i, j) == 0.0)
}

/// True if [`surely_non_zero`] holds for some component. Hosted targets test the three
/// components at once, in lanes 0, 1, 2 (x, y, z) of [`F4`], each lane with the operations
/// of the scalar test; bare-metal targets call the scalar test per component (flash).
#[inline(always)]
fn some_component_surely_non_zero(v: &[[f32; 3]; 3]) -> bool {
    if cfg!(target_os = "none") {
        return COMPONENTS.iter().any(|&(i, j)| surely_non_zero(v, i, j));
    }
    let a = vector(&v[0]);
    let (e1, e2) = (vector(&v[1]).sub(a), vector(&v[2]).sub(a));
    // Lane k: the products of component k, `(y, z)`, `(z, x)`, `(x, y)`.
    let (p, q) = (e1.yzx().mul(e2.zxy()), e1.zxy().mul(e2.yzx()));
    let bound = p
        .abs()
        .add(q.abs())
        .mul(F4::splat(SURE_REL))
        .add(F4::splat(SURE_ABS));
    // Nothing here is NaN (coordinates are finite and at most 2^40), so "not <=" is ">".
    p.sub(q).abs().le_mask(bound) & 0b111 != 0b111
}

/// [`surely_non_zero`]'s relative error bound (2^-21).
const SURE_REL: f32 = 1.0 / 2_097_152.0;
/// [`surely_non_zero`]'s absolute error bound, for underflow (2^-120).
const SURE_ABS: f32 = 7.523_164e-37;

/// True if component `(i, j)` of `(b - a) × (c - a)` evaluated in `f32` exceeds its rounding
/// error bound (differences, products and their difference: under `4·2^-24` of the products'
/// magnitudes, bounded here by `2^-21` of them plus `2^-120` for underflow), so is surely
/// non-zero. Bare-metal targets keep one copy, which takes the four differences it needs on
/// each call (flash: passing the edges in costs more code than the subtractions).
#[cfg_attr(not(target_os = "none"), inline(always))]
#[cfg_attr(target_os = "none", inline(never))]
fn surely_non_zero(v: &[[f32; 3]; 3], i: Axis, j: Axis) -> bool {
    let [a, b, c] = v;
    let edge = |p: &[f32; 3], k: Axis| axis(p, k) - axis(a, k);
    let (p, q) = (edge(b, i) * edge(c, j), edge(b, j) * edge(c, i));
    abs(p - q) > (abs(p) + abs(q)) * SURE_REL + SURE_ABS
}

/// Component `(i, j)` of `a × b + b × c + c × a`, which is that of `(b - a) × (c - a)`, with its
/// exact sign, zero exactly when it is zero ([`exact_cross_sum`]). One copy in flash for every
/// exact decision of the triangle test: its callers pass the points and axes, not the factors.
#[inline(never)]
fn exact_cross(v: &[[f32; 3]; 3], i: Axis, j: Axis) -> f32 {
    let [a, b, c] = v;
    exact_cross_sum([
        axis(a, i),
        axis(a, j),
        axis(b, i),
        axis(b, j),
        axis(c, i),
        axis(c, j),
    ])
}

/// The slab test of one box: the IEEE operations of one lane of `Numerics::slab_pair`, in the
/// same order, so the same bits. Bare-metal targets run it once per box: their lanes are
/// scalar code anyway, and one copy of it is the smallest in flash.
#[cfg_attr(not(target_os = "none"), inline(always))]
#[cfg_attr(target_os = "none", inline(never))]
fn slab_box(r: &FloatRay, (lo, hi): (&[f32; 3], &[f32; 3]), t_min: f32, t_max: f32) -> Option<f32> {
    let (mut near, mut far) = (t_min, t_max);
    for i in 0..3 {
        let a = (lo[i] - r.o_lo[i]) * r.inv[i];
        let b = (hi[i] - r.o_hi[i]) * r.inv[i];
        let (n, f) = (if a < b { a } else { b }, if a > b { a } else { b });
        near = if n > near { n } else { near };
        far = if f < far { f } else { far };
    }
    (near <= far * WIDEN).then_some(near)
}

impl Scalar for f32 {
    type Vec3 = glam::Vec3;

    const ZERO: Self = 0.0;
    const FAR: Self = f32::INFINITY;
    const NAME: &'static str = "f32";

    fn to_f32(self) -> f32 {
        self
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn from_f32_saturating(x: f32) -> Self {
        if x.is_nan() {
            0.0
        } else {
            x
        }
    }
    fn coord_from_f32(x: f32) -> Result<Self, PointError> {
        check_coord(x).map(|()| x)
    }
    fn vec_to_array(v: glam::Vec3) -> [f32; 3] {
        v.to_array()
    }
    fn array_to_vec(a: [f32; 3]) -> glam::Vec3 {
        glam::Vec3::from_array(a)
    }
    fn check_point(p: [f32; 3]) -> Result<(), PointError> {
        p.iter().try_for_each(|&x| check_coord(x))
    }
    fn check_radius(r: f32) -> Result<(), PointError> {
        check_coord(r)?;
        if r < 0.0 {
            Err(PointError::NegativeRadius)
        } else {
            Ok(())
        }
    }
    fn ray_origin(ray: &FloatRay) -> [f32; 3] {
        let [x, y, z, _] = ray.origin;
        [x, y, z]
    }
    fn ray_dir(ray: &FloatRay) -> [f32; 3] {
        let [x, y, z, _] = ray.dir;
        [x, y, z]
    }
}

impl Numerics for f32 {
    type RayData = FloatRay;
    const LOWEST: f32 = f32::NEG_INFINITY;

    // On hosted targets the ray constructors are inlined down to `FloatRay::new`, so a ray is
    // built where it is stored. Returned through memory and then moved into the `Ray`, it was
    // re-read with 16-byte loads over narrower stores, which stall on store forwarding on x86:
    // measured at about a tenth of a primary-only render's time. Bare-metal targets
    // (`target_os = "none"`) leave inlining to the optimiser: forced, it grew the renderer by
    // 12 KB of flash (more than a Cortex-M0 test image holds), for a stall their cores lack.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn ray_data(origin: [f32; 3], dir: [f32; 3]) -> Result<FloatRay, RayError> {
        FloatRay::new(origin, dir)
    }
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn ray_data_from_f32(origin: [f32; 3], dir: [f32; 3]) -> Result<FloatRay, RayError> {
        FloatRay::new(origin, dir)
    }
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn set_ray_data_from_f32(
        data: &mut FloatRay,
        origin: [f32; 3],
        dir: [f32; 3],
    ) -> Result<(), RayError> {
        data.set(origin, dir)
    }
    fn ray_moved(ray: &FloatRay, origin: [f32; 3]) -> Result<FloatRay, RayError> {
        ray.moved(origin)
    }
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn ray_redirected_f32(ray: &FloatRay, dir: [f32; 3]) -> Result<FloatRay, RayError> {
        FloatRay::along(Self::ray_origin(ray), ray.o_lo, ray.o_hi, dir)
    }

    fn pad_bounds(lo: [f32; 3], hi: [f32; 3]) -> ([f32; 3], [f32; 3]) {
        let d = margin_offset(max_abs(&lo).max_of(max_abs(&hi)));
        let ([a, b, c], [x, y, z]) = (lo, hi);
        ([a - d, b - d, c - d], [x + d, y + d, z + d])
    }

    #[inline(always)]
    fn slab(r: &FloatRay, lo: &[f32; 3], hi: &[f32; 3], t_min: f32, t_max: f32) -> Option<f32> {
        if cfg!(target_os = "none") {
            return slab_box(r, (lo, hi), t_min, t_max);
        }
        let [hit, _] = Self::slab_pair(r, (lo, hi), (lo, hi), t_min, t_max);
        hit
    }

    #[inline(always)]
    fn slab_pair(
        r: &FloatRay,
        a: (&[f32; 3], &[f32; 3]),
        b: (&[f32; 3], &[f32; 3]),
        t_min: f32,
        t_max: f32,
    ) -> [Option<f32>; 2] {
        if cfg!(target_os = "none") {
            return [slab_box(r, a, t_min, t_max), slab_box(r, b, t_min, t_max)];
        }
        // Per box and axis (lanes x, y, z, z), the plane distances, then the sequential fold
        // `t_near = max(t_min, near_x, near_y, near_z)` (and `t_far` likewise with `min`), run
        // for both boxes side by side in lanes 0 and 1. Every lane sees exactly the operations
        // of a scalar loop in the same order, so the bits are those of scalar code.
        let (o_lo, o_hi, inv) = (F4::new(r.o_lo), F4::new(r.o_hi), F4::new(r.inv));
        let planes = |(lo, hi): (&[f32; 3], &[f32; 3])| {
            let a = F4::new([lo[0], lo[1], lo[2], lo[2]]).sub(o_lo).mul(inv);
            let b = F4::new([hi[0], hi[1], hi[2], hi[2]]).sub(o_hi).mul(inv);
            // 0 * inf = NaN happens only for a zero direction component whose shifted origin
            // lies exactly on a plane, i.e. the parallel ray is just outside the slab. A NaN in
            // `a` makes near and far `b` (+inf or -inf: the box is rejected, exactly); a NaN in
            // `b` makes both NaN, which the folds ignore (`max(NaN, acc) = acc`): the box is
            // kept, conservatively.
            (a.min(b), a.max(b))
        };
        let (near_a, far_a) = planes(a);
        let (near_b, far_b) = planes(b);
        let fold = |va: F4, vb: F4, start: f32, pick: fn(F4, F4) -> F4| {
            let xy = va.unpack_lo(vb); // [a.x, b.x, a.y, b.y]
            let zz = va.unpack_hi(vb); // [a.z, b.z, ..]
            let acc = pick(xy, F4::splat(start));
            let acc = pick(xy.high_half(), acc);
            pick(zz, acc)
        };
        let t_near = fold(near_a, near_b, t_min, F4::max);
        let t_far = fold(far_a, far_b, t_max, F4::min);
        let inside = t_near.le_mask(t_far.mul(F4::splat(WIDEN)));
        [
            (inside & 1 != 0).then(|| t_near.lane0()),
            (inside & 2 != 0).then(|| t_near.lane1()),
        ]
    }

    #[inline(always)]
    fn slab_axis(r: &FloatRay, axis: usize, lo: f32, hi: f32) -> (f32, f32) {
        // The same IEEE operations as one lane of `slab`, so the same bits.
        let i = axis.min(2);
        let a = (lo - r.o_lo[i]) * r.inv[i];
        let b = (hi - r.o_hi[i]) * r.inv[i];
        let near = if a < b { a } else { b };
        let far = if a > b { a } else { b };
        // `slab` ignores a lane whose `near` is NaN (NaN in `b`); a NaN in `a` leaves (b, b).
        if near.is_nan() {
            (f32::NEG_INFINITY, f32::INFINITY)
        } else {
            (near, Self::widen(far))
        }
    }

    #[inline(always)]
    fn axis_negative(r: &FloatRay, axis: usize) -> bool {
        r.inv[axis.min(2)] < 0.0
    }

    #[inline(always)]
    fn order_bits(t: f32) -> u32 {
        t.to_bits()
    }

    #[inline(always)]
    fn widen(t: f32) -> f32 {
        // Only non-negative ends matter (t_near >= t_min >= 0); negative ones stay negative.
        // Multiplying keeps ±inf as they are.
        t * WIDEN
    }

    #[inline(always)]
    fn triangle_t(r: &FloatRay, v: &[[f32; 3]; 3], t_min: f32, t_max: f32) -> Option<f32> {
        // Translate to the ray origin, permute so the dominant axis is z, and shear. (Borrowed:
        // destructuring the array by value copies the vertices on bare metal.)
        let sheared = r.sheared(v);
        let [a, b, c] = &sheared;
        // Edge functions; two-sided, so reject only if the signs differ. (Non-short-circuit
        // operators: one branch instead of six hard-to-predict ones.)
        let [eu, ev, ew] = FloatRay::edges(a, b, c);
        let negative = (eu < 0.0) | (ev < 0.0) | (ew < 0.0);
        let positive = (eu > 0.0) | (ev > 0.0) | (ew > 0.0);
        if negative & positive {
            return None;
        }
        if eu + ev + ew == 0.0 {
            return None; // degenerate triangle, or a ray in its plane
        }
        // The signs above decide hit or miss (watertight). For the distance, recompute the
        // edge functions with exact products (double-f32): on slivers the f32 values keep too
        // few bits for an accurate t. Rare path: candidates only.
        let t = FloatRay::candidate_t(a, b, c)?;
        if !(t >= t_min && t <= t_max) {
            return None;
        }
        // Rare path, hits only: drop what rounding made of degenerate or edge-on triangles.
        if !r.point_near_box(t, v) || zero_area(v) {
            return None;
        }
        Some(t)
    }

    fn triangle_uv(r: &FloatRay, v: &[[f32; 3]; 3]) -> (f32, f32) {
        let sheared = r.sheared(v);
        let [a, b, c] = &sheared;
        // Clamped to [0, 1] as in fixed point: the exact solve can disagree in sign with the f32
        // edge functions that accepted the hit by a few subnormals (found by fuzzing).
        let unit = |w: f32| if w > 0.0 { w.min_of(1.0) } else { 0.0 };
        FloatRay::solve(a, b, c).map_or((0.0, 0.0), |(_, u, v)| (unit(u), unit(v)))
    }

    fn sphere_t(
        r: &FloatRay,
        center: &[f32; 3],
        radius: f32,
        t_min: f32,
        t_max: f32,
    ) -> Option<f32> {
        // Hearn-Baker style discriminant, which stays accurate for small spheres far away
        // (Haines et al., "Precision Improvements for Ray/Sphere Intersection", RT Gems ch. 7).
        let d = r.dir;
        let f = [
            r.origin[0] - center[0],
            r.origin[1] - center[1],
            r.origin[2] - center[2],
        ];
        let a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let b = -(f[0] * d[0] + f[1] * d[1] + f[2] * d[2]);
        let s = b / a;
        let l = [f[0] + s * d[0], f[1] + s * d[1], f[2] + s * d[2]];
        let disc = radius * radius - (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
        // NaN (only from overflow) counts as a miss, like a negative discriminant.
        if disc.is_nan() || disc < 0.0 {
            return None;
        }
        let c = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] - radius * radius;
        let q = b + libm::copysignf(sqrtf(a * disc), b);
        if q == 0.0 {
            return None; // zero radius seen from its own centre
        }
        let (t0, t1) = (c / q, q / a);
        let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        let (lo, hi) = Self::sphere_bounds(center, radius);
        let box_ = [lo, hi, hi];
        let ok = |t: f32| t >= t_min && t <= t_max && r.point_near_box(t, &box_);
        if ok(near) {
            Some(near)
        } else if ok(far) {
            Some(far)
        } else {
            None
        }
    }

    #[inline(always)]
    fn slab4(
        r: &FloatRay,
        lo: &[[f32; 4]; 3],
        hi: &[[f32; 4]; 3],
        t_min: f32,
        t_max: f32,
    ) -> (u32, [f32; 4]) {
        super::wide::slab4(r.o_lo, r.o_hi, r.inv, WIDEN, lo, hi, t_min, t_max)
    }

    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    #[inline(always)]
    unsafe fn slab8_avx2(
        r: &FloatRay,
        lo: &[[f32; 8]; 3],
        hi: &[[f32; 8]; 3],
        t_min: f32,
        t_max: f32,
    ) -> (u32, [f32; 8]) {
        // SAFETY: the caller guarantees AVX2, which includes AVX, the one feature
        // `slab8_avx2` enables.
        unsafe { super::wide::slab8_avx2(r.o_lo, r.o_hi, r.inv, WIDEN, lo, hi, t_min, t_max) }
    }

    fn sphere_bounds(center: &[f32; 3], radius: f32) -> ([f32; 3], [f32; 3]) {
        let mut lo = [0.0; 3];
        let mut hi = [0.0; 3];
        for i in 0..3 {
            lo[i] = center[i] - radius;
            hi[i] = center[i] + radius;
        }
        (lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_moves_one_ulp_each_way() {
        assert_eq!(step(1.0, true), f32::from_bits(1.0f32.to_bits() + 1));
        assert_eq!(step(1.0, false), f32::from_bits(1.0f32.to_bits() - 1));
        assert_eq!(step(-1.0, true), f32::from_bits((-1.0f32).to_bits() - 1));
        assert!(step(0.0, true) > 0.0 && step(0.0, false) < 0.0);
    }

    use crate::scalar::xorshift as next;

    /// `unit_dir_and_inverse` takes `d` as given exactly when `normalized` returns it bit for
    /// bit, its quotient by `1 - 2^-24` is `normalized`'s, and its inverse is the quotient
    /// `1 / dir` of that unit vector: checked on unit vectors rounded from `f64`
    /// (with tiny and zero components, of every sign and order), which take a shortcut most of
    /// the time, and on their neighbours one ulp away.
    #[test]
    fn unit_dir_shortcut_is_the_normalisation() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut unit = || (next(&mut state) >> 11) as f64 / 9_007_199_254_740_992.0 * 2.0 - 1.0;
        let (mut shortcut, mut below, mut total) = (0usize, 0usize, 0usize);
        for i in 0..400_000 {
            let mut v = [unit(), unit(), unit()];
            match i % 8 {
                0 => v[i % 3] *= 1e-30,
                1 => v[(i / 8) % 3] = 0.0,
                2 => (v[0], v[1]) = (v[0] * 1e-21, v[1] * 1e-25),
                _ => {}
            }
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if len == 0.0 {
                continue;
            }
            let d = v.map(|x| (x / len) as f32);
            let k = (i / 16) % 3;
            let mut nudged = d;
            nudged[k] = step(d[k], i % 2 == 0);
            for d in [d, nudged] {
                let (Ok((got, inv)), Ok(want)) = (unit_dir_and_inverse(d), normalized(d)) else {
                    panic!("{d:?} rejected");
                };
                let got = got.to_array();
                assert_eq!(got.map(f32::to_bits), want.map(f32::to_bits), "{d:?}");
                let recip = want.map(|x| (1.0 / x).to_bits());
                assert_eq!(inv.to_array().map(f32::to_bits), recip, "1 / {d:?}");
                total += 1;
                let q = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                shortcut += usize::from(q == 1.0 || q == 1.0 + f32::EPSILON);
                below += usize::from(q == BELOW_ONE);
            }
        }
        assert!(
            shortcut > total / 3,
            "shortcut taken {shortcut} of {total} times"
        );
        assert!(below > total / 20, "q = 1 - 2^-24 {below} of {total} times");
        for bad in [[f32::NAN, 0.0, 1.0], [f32::INFINITY, 0.0, 0.0], [0.0; 3]] {
            assert!(unit_dir_and_inverse(bad).is_err(), "{bad:?}");
        }
    }

    /// `shear_axes` against the definition written as branches: on every direction made of
    /// the magnitudes 0, 1, 2 (so with ties of every kind) with either sign on each component
    /// (`-0.0` too), and on random directions.
    #[test]
    fn shear_axes_are_the_dominant_axis_and_the_others_in_winding_order() {
        let reference = |d: [f32; 3]| {
            let a = d.map(abs);
            let kz = if a[0] >= a[1] && a[0] >= a[2] {
                0
            } else if a[1] >= a[2] {
                1
            } else {
                2
            };
            let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if d[kz] < 0.0 {
                [ky, kx, kz]
            } else {
                [kx, ky, kz]
            }
        };
        let check = |d: [f32; 3]| {
            let got = shear_axes(F4::new(lanes(d))).map(|k| k as usize);
            assert_eq!(got, reference(d), "{d:?}");
        };
        let mut tried = 0;
        for code in 0..6usize.pow(3) {
            let d: [f32; 3] = core::array::from_fn(|i| {
                let digit = code / 6usize.pow(i as u32) % 6;
                let magnitude = (digit / 2) as f32;
                if digit % 2 == 1 {
                    -magnitude
                } else {
                    magnitude
                }
            });
            if d != [0.0; 3] {
                check(d);
                tried += 1;
            }
        }
        assert!(tried > 100, "{tried} directions");
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..10_000 {
            let d: [f32; 3] =
                core::array::from_fn(|_| (next(&mut state) >> 40) as f32 / 8_388_608.0 - 1.0);
            if d != [0.0; 3] {
                check(d);
            }
        }
    }

    /// The next representable value above (`up`) or below `x`.
    fn step(x: f32, up: bool) -> f32 {
        <f32 as crate::scalar::sealed::Spawn>::step(x, up)
    }

    /// `x` moved by `delta` in the given direction, and by at least one ulp: what
    /// [`margin_offset`] promises, the long way.
    fn shift(x: f32, delta: f32, up: bool) -> f32 {
        let y = if up { x + delta } else { x - delta };
        if y == x {
            step(x, up)
        } else {
            y
        }
    }

    /// Magnitudes of every kind: zeros, subnormals, the normal threshold, up to the limit.
    const COORDS: [f32; 19] = [
        0.0,
        -0.0,
        f32::from_bits(1),
        -f32::from_bits(1),
        3.0 * f32::from_bits(1),
        1e-40,
        -1e-39,
        1.17e-38,
        1e-30,
        1e-20,
        0.5,
        1.0,
        -1.0,
        3.0,
        1234.5,
        -1e6,
        7.3e11,
        F32_COORD_LIMIT,
        -F32_COORD_LIMIT,
    ];

    #[test]
    fn shifted_origins_move_each_lane_as_shift_does() {
        for &a in &COORDS {
            for &b in &COORDS {
                for &c in &COORDS {
                    let origin = [a, b, c];
                    let o_max = abs(a).max_of(abs(b)).max_of(abs(c));
                    let delta = o_max * MARGIN;
                    let (lo, hi) = FloatRay::shifted_origins(origin);
                    for i in 0..4 {
                        let x = origin[i.min(2)];
                        // Equal as values (a zero's sign may differ), strictly beyond `x`.
                        assert!(lo[i] == shift(x, delta, true) && lo[i] > x, "{origin:?}");
                        assert!(hi[i] == shift(x, delta, false) && hi[i] < x, "{origin:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn padded_bounds_move_each_coordinate_as_shift_does() {
        let mut st = 0x9add_0000_0000_0001u64;
        for _ in 0..100_000 {
            let mut pick = || COORDS[(next(&mut st) % COORDS.len() as u64) as usize];
            let (p, q): ([f32; 3], [f32; 3]) = ([pick(), pick(), pick()], [pick(), pick(), pick()]);
            let lo: [f32; 3] = core::array::from_fn(|i| p[i].min_of(q[i]));
            let hi: [f32; 3] = core::array::from_fn(|i| p[i].max_of(q[i]));
            let m = (0..3).fold(0.0f32, |m, i| m.max_of(abs(lo[i])).max_of(abs(hi[i])));
            let (plo, phi) = <f32 as Numerics>::pad_bounds(lo, hi);
            for i in 0..3 {
                assert!(plo[i] == shift(lo[i], m * MARGIN, false) && plo[i] < lo[i]);
                assert!(phi[i] == shift(hi[i], m * MARGIN, true) && phi[i] > hi[i]);
            }
        }
    }

    /// Sheared triangles around the +z axis (the ray), of every shape a distance solve meets:
    /// well conditioned, slivers (nearly collinear), tiny, huge, far away, behind the origin,
    /// at mixed depths, and on exactly representable depths.
    fn candidates(count: usize) -> impl Iterator<Item = [[f32; 3]; 3]> {
        let mut state = 0x0f11_7e12_0000_0001u64;
        (0..count).map(move |i| {
            let mut unit = || (next(&mut state) >> 40) as f32 / 16_777_216.0 * 2.0 - 1.0;
            let scale = libm::exp2f((i % 61) as f32 - 30.0);
            let depth = libm::exp2f((i % 23) as f32 - 8.0) * if i % 5 == 0 { -1.0 } else { 1.0 };
            let mut v = [[0.0f32; 3]; 3];
            for p in &mut v {
                let z = if i % 7 == 3 {
                    depth
                } else {
                    depth * (1.0 + 0.5 * unit())
                };
                *p = [unit() * scale, unit() * scale, z];
            }
            if i % 3 == 1 {
                // A sliver: the third vertex nearly on the line through the first two.
                let f = 0.5 + 0.25 * unit();
                let (p0, p1) = (v[0], v[1]);
                for ((x, a), b) in v[2].iter_mut().zip(p0).zip(p1).take(2) {
                    *x = a + f * (b - a) + unit() * scale * 1e-6;
                }
            }
            v
        })
    }

    #[cfg(not(target_os = "none"))]
    #[test]
    fn the_certified_distance_is_the_double_f32_solve_bit_for_bit() {
        let (mut solved, mut certified) = (0usize, 0usize);
        for [a, b, c] in candidates(1_000_000) {
            let exact = FloatRay::solved_t(&a, &b, &c);
            solved += usize::from(exact.is_some());
            if let Some(t) = rounded::certified_t(&a, &b, &c) {
                certified += 1;
                assert_eq!(
                    Some(t.to_bits()),
                    exact.map(f32::to_bits),
                    "{a:?} {b:?} {c:?}"
                );
            }
        }
        // The shortcut decides most of them (slivers and triangles the ray misses by far,
        // whose det cancels, fall back): it is not vacuous.
        assert!(
            solved > 500_000 && certified * 2 > solved,
            "{certified} of {solved} certified"
        );
    }

    #[test]
    fn slab_box_is_one_lane_of_slab_pair() {
        // Coordinates on a coarse grid, so rays start on planes and run along them (zero
        // direction components: the NaN cases of the slab test) as often as not.
        fn coord(state: &mut u64) -> f32 {
            ((next(state) % 9) as f32 - 4.0) * 0.5
        }
        let mut st = 0x51ab_0b0c_0000_0003u64;
        let mut tested = 0;
        for _ in 0..200_000 {
            let mut point = || [coord(&mut st), coord(&mut st), coord(&mut st)];
            let (origin, dir) = (point(), point());
            let (p, q, u, w) = (point(), point(), point(), point());
            let Ok(r) = FloatRay::new(origin, dir) else {
                continue;
            };
            let lo1: [f32; 3] = core::array::from_fn(|i| p[i].min_of(q[i]));
            let hi1: [f32; 3] = core::array::from_fn(|i| p[i].max_of(q[i]));
            let lo2: [f32; 3] = core::array::from_fn(|i| u[i].min_of(w[i]));
            let hi2: [f32; 3] = core::array::from_fn(|i| u[i].max_of(w[i]));
            let t_max = [f32::INFINITY, 1.0, 3.5][(next(&mut st) % 3) as usize];
            let pair = <f32 as Numerics>::slab_pair(&r, (&lo1, &hi1), (&lo2, &hi2), 0.0, t_max);
            let single = [
                slab_box(&r, (&lo1, &hi1), 0.0, t_max),
                slab_box(&r, (&lo2, &hi2), 0.0, t_max),
            ];
            assert_eq!(
                pair.map(|t| t.map(f32::to_bits)),
                single.map(|t| t.map(f32::to_bits)),
                "{origin:?} {dir:?} {lo1:?} {hi1:?} {lo2:?} {hi2:?}"
            );
            tested += usize::from(pair.iter().any(Option::is_some));
        }
        assert!(tested > 10_000, "{tested} rays hit a box");
    }

    #[test]
    fn zero_direction_components_give_signed_infinite_inverse() {
        let r = FloatRay::new([0.0; 3], [0.0, -0.0, 1.0]).unwrap();
        assert_eq!(r.inv[0], f32::INFINITY);
        assert_eq!(r.inv[1], f32::NEG_INFINITY);
        assert!(!r.inv.iter().any(|x| x.is_nan()));
    }

    /// Triangles for the checks of a hit: [`candidates`], the same with a coordinate axis
    /// flattened (faces of axis-aligned boxes, whose normals have zero components), and
    /// degenerate ones (collinear, coincident vertices, a point).
    fn hit_checks_triangles() -> impl Iterator<Item = [[f32; 3]; 3]> {
        candidates(3000).flat_map(|v| {
            let flat = |k: usize| {
                v.map(|mut p| {
                    p[k] = v[0][k];
                    p
                })
            };
            let [a, b, _] = v;
            let mid = core::array::from_fn(|k| a[k] + 0.5 * (b[k] - a[k]));
            [
                v,
                flat(0),
                flat(1),
                flat(2),
                [a, b, mid],
                [a, a, b],
                [a, a, a],
            ]
        })
    }

    #[test]
    fn surely_non_zero_in_lanes_is_the_scalar_test_per_component() {
        let (mut tested, mut sure) = (0, 0);
        for v in hit_checks_triangles() {
            let scalar = COMPONENTS.iter().any(|&(i, j)| surely_non_zero(&v, i, j));
            assert_eq!(some_component_surely_non_zero(&v), scalar, "{v:?}");
            tested += 1;
            sure += usize::from(scalar);
        }
        assert!(
            sure > tested / 2 && sure < tested,
            "{sure} of {tested} surely non-zero"
        );
    }

    #[test]
    fn point_near_box_in_lanes_is_the_per_axis_loop() {
        let mut state = 0x5eed_0000_0000_0011u64;
        let (mut inside, mut outside) = (0, 0);
        for (n, v) in hit_checks_triangles().enumerate() {
            let mut unit = || (next(&mut state) >> 40) as f32 / 16_777_216.0 * 2.0 - 1.0;
            // Origins small and large against the triangle, so either can set the margin.
            let origin = [unit(), unit(), unit()].map(|x| x * libm::exp2f((n % 41) as f32 - 10.0));
            let Ok(r) = FloatRay::new(origin, [unit(), unit(), 1.0]) else {
                continue;
            };
            let e = max_abs(&origin).max_of(max_abs(v.as_flattened())) * (MARGIN * 0.5);
            // Distances around the one where the ray meets the first vertex's z plane.
            let t = libm::fabsf(v[0][2] - origin[2]) * (1.0 + 0.01 * unit());
            // And rays aimed at points half a margin and one and a half outside the box's
            // low x face (the rounding of `origin + t·dir` is far below the margin).
            let aimed = [0.5f32, 1.5].map(|k| {
                let lo_x = v[0][0].min_of(v[1][0]).min_of(v[2][0]);
                let target = [lo_x - k * e, v[0][1], v[0][2]];
                let d: [f32; 3] = core::array::from_fn(|i| target[i] - origin[i]);
                let len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                (FloatRay::new(origin, d), len)
            });
            let cases = [(Ok(r), t), aimed[0], aimed[1]];
            for (r, t) in cases {
                let Ok(r) = r else { continue };
                let want = r.point_near_box_per_axis(t, &v);
                assert_eq!(r.point_near_box(t, &v), want, "{v:?} {origin:?} {t}");
                inside += usize::from(want);
                outside += usize::from(!want);
            }
        }
        assert!(
            inside > 100 && outside > 100,
            "{inside} inside, {outside} outside"
        );
    }
}
