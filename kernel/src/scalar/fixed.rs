//! Fixed-point mode: [`I16F16`] coordinates, Q2.30 unit directions, exact integer tests.
//!
//! Widths (raw integers, `b` = bits of magnitude):
//! - coordinates: Q16.16 in `i32`, limited to `|x| <= 8192` (raw `<= 2^29`), so a difference of
//!   two points fits 31 bits and every in-scene distance (`<= 8192·2·√3 < 32768`) fits Q16.16;
//! - directions: unit length in Q2.30 (raw `|d| <= 2^30`);
//! - triangle edge functions `U = C'·(B'×D)`: `B'×D` is `< 2^61` in `i64`, the dot is `< 2^93` in
//!   `i128`, so the signs are exact: shared edges and vertices are never missed or hit twice
//!   by a gap (no fallback needed, unlike `f32`);
//! - hit distance: `t = floor(T·2^30 / det)` in `i128` (deterministic, not exact);
//! - slab test: `(plane - origin) · (2^62 / d) >> 32` in `i128`, padded by 2 raw units each way,
//!   which bounds the rounding of the reciprocal, so boxes are never culled wrongly. The 4-wide
//!   BVH's test of four boxes at once runs in `f32` lanes where there are vector lanes
//!   (`wide::slab4_fixed`: exact `i32` plane distances, relative margins), which may visit
//!   other nodes than the integer test would but finds the same hits.

use super::sealed::Numerics;
use super::Scalar;
use super::{PointError, RayError};
use core::ops::{Add, Div, Mul, Neg, Sub};

/// A signed fixed-point number with 16 integer and 16 fraction bits (`value = raw / 65536`).
///
/// Range `[-32768, 32768)` with resolution `2^-16 ≈ 1.5e-5`. Arithmetic operators
/// **saturate** at the range ends (never wrap, never panic); multiplication and division round
/// to nearest, ties away from zero. Kernel geometry is further limited to
/// [`FIXED_COORD_LIMIT`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct I16F16(pub i32);

/// Largest coordinate magnitude (world units) accepted in fixed-point mode: 8192 = 2^13.
pub const FIXED_COORD_LIMIT: f32 = 8192.0;
const LIMIT_RAW: i32 = 1 << 29;
const ONE_RAW: i32 = 1 << 16;
/// Raw value of 1.0 in Q2.30.
const DIR_ONE: f64 = (1u64 << 30) as f64;
/// Slab padding in raw units; bounds the error of the rounded reciprocal (< 2 raw units).
const SLAB_PAD: i64 = 2;

impl I16F16 {
    /// 0.
    pub const ZERO: Self = Self(0);
    /// 1.
    pub const ONE: Self = Self(ONE_RAW);
    /// Largest value, `32768 - 2^-16`.
    pub const MAX: Self = Self(i32::MAX);
    /// Smallest value, `-32768`.
    pub const MIN: Self = Self(i32::MIN);

    /// From raw bits.
    #[must_use]
    pub const fn from_raw(raw: i32) -> Self {
        Self(raw)
    }
    /// Raw bits.
    #[must_use]
    pub const fn raw(self) -> i32 {
        self.0
    }
    /// From an integer, saturating.
    #[must_use]
    pub const fn from_int(x: i32) -> Self {
        Self(x.saturating_mul(ONE_RAW))
    }
    /// Rounds `x` to nearest (ties away from zero), saturating; NaN gives zero.
    #[must_use]
    pub fn from_f32(x: f32) -> Self {
        // f64 holds x·65536 exactly; `as i32` saturates and maps NaN to 0.
        Self(to_round(x as f64 * ONE_RAW as f64) as i32)
    }
    /// Converts to `f32`, rounding to nearest (exact when `|raw| < 2^24`).
    #[must_use]
    pub fn to_f32(self) -> f32 {
        (self.0 as f64 / ONE_RAW as f64) as f32
    }
}

/// A value that an `as` conversion to an integer turns into `libm::round(v)` (nearest, ties away
/// from zero; `as` then saturates and maps NaN to 0).
///
/// Hosted targets add the largest `f64` below one half, with `v`'s sign, for `as` to truncate:
/// below 2^52 the sum reaches the next integer (in magnitude) exactly when `v`'s fraction is at
/// least one half (at one half it falls at most half an ulp short and rounds onto it; just
/// below, it stays short), and from 2^52 on every `f64` is an integer that the sum rounds back
/// to. One addition instead of `libm::round`'s bit manipulation, which held up every ray's
/// construction. Bare-metal targets keep `libm::round`: no `f64` arithmetic there.
#[inline(always)]
fn to_round(v: f64) -> f64 {
    #[cfg(not(target_os = "none"))]
    {
        const BELOW_HALF: f64 = 0.499_999_999_999_999_94;
        v + libm::copysign(BELOW_HALF, v)
    }
    #[cfg(target_os = "none")]
    {
        libm::round(v)
    }
}

/// A unit vector in Q2.30 raw units: each component `u` as `to_round(u · 2^30)`.
#[inline(always)]
fn q30(unit: [f64; 3]) -> [i64; 3] {
    unit.map(|u| to_round(u * DIR_ONE) as i64)
}

/// How close to a tie (an integer plus one half, in raw units) the direct normalisation may
/// come before [`q30_from_f32`] defers to the scaled one: `2^-16`.
const TIE_BAND: f64 = 1.0 / 65_536.0;

/// `q30(unit_dir_from_f32(d)?)`, the direction of a ray given in `f32`, bit for bit; about one
/// direction in 10^4 pays for both normalisations.
///
/// The direct normalisation (`float::unit_dir_direct_f32`: one square root and one division,
/// against the scaled one's two divisions besides) is rounded instead, and kept when every
/// component lies more than [`TIE_BAND`] from a tie. The two are within relative errors of
/// `3·2^-53` and `6.5·2^-53` of the exact unit vector (their docs), so scaled by `2^30` each
/// component differs by at most `9.5·2^-23 < 2^-19` raw units between them: both lie strictly
/// between the same two ties, where `to_round` returns the same integer (the nearest; see its
/// doc). Zero and non-finite directions take the scaled path, which returns their errors.
#[cfg_attr(not(target_os = "none"), inline(always))]
#[cfg_attr(target_os = "none", inline)]
fn q30_from_f32(d: [f32; 3]) -> Result<[i64; 3], RayError> {
    match direct_q30(d) {
        Some(k) => Ok(k),
        None => Ok(q30(super::float::unit_dir_from_f32(d)?)),
    }
}

/// The direct normalisation of `d` rounded to Q2.30, if `d` is finite and not zero and every
/// component lies more than [`TIE_BAND`] from a tie (see [`q30_from_f32`]).
#[cfg_attr(not(target_os = "none"), inline(always))]
#[cfg_attr(target_os = "none", inline)]
fn direct_q30(d: [f32; 3]) -> Option<[i64; 3]> {
    let v = super::float::unit_dir_direct_f32(d)?.map(|u| u * DIR_ONE);
    let k = v.map(|x| to_round(x) as i64);
    // `v - k` is exact: at most one half apart, and `k` is zero or within a factor two.
    let clear = |i: usize| libm::fabs(v[i] - k[i] as f64) < 0.5 - TIE_BAND;
    (clear(0) & clear(1) & clear(2)).then_some(k)
}

fn saturate(x: i64) -> I16F16 {
    I16F16(if x > i32::MAX as i64 {
        i32::MAX
    } else if x < i32::MIN as i64 {
        i32::MIN
    } else {
        x as i32
    })
}

/// `round(n / d)` for `d > 0`, ties away from zero. (Checked division: callers never pass
/// `d <= 0`, and the check keeps a panic path out of the code; 0 would be the answer.)
fn div_round(n: i128, d: i128) -> i128 {
    let half = d / 2;
    if n >= 0 {
        (n + half).checked_div(d).unwrap_or(0)
    } else {
        -(-n + half).checked_div(d).unwrap_or(0)
    }
}

impl Add for I16F16 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self(self.0.saturating_add(o.0))
    }
}
impl Sub for I16F16 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self(self.0.saturating_sub(o.0))
    }
}
impl Neg for I16F16 {
    type Output = Self;
    fn neg(self) -> Self {
        Self(self.0.saturating_neg())
    }
}
impl Mul for I16F16 {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        saturate(div_round(self.0 as i128 * o.0 as i128, ONE_RAW as i128) as i64)
    }
}
impl Div for I16F16 {
    type Output = Self;
    /// Division by zero saturates to `MAX`/`MIN` by the sign of the dividend (zero for 0/0).
    fn div(self, o: Self) -> Self {
        if o.0 == 0 {
            return match self.0 {
                0 => Self::ZERO,
                x if x > 0 => Self::MAX,
                _ => Self::MIN,
            };
        }
        let (n, d) = ((self.0 as i128) << 16, o.0 as i128);
        let q = if d > 0 {
            div_round(n, d)
        } else {
            div_round(-n, -d)
        };
        saturate(q.clamp(i64::MIN as i128, i64::MAX as i128) as i64)
    }
}

/// A point or vector of [`I16F16`], the public vector type of fixed-point mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Vec3x {
    /// x.
    pub x: I16F16,
    /// y.
    pub y: I16F16,
    /// z.
    pub z: I16F16,
}

impl Vec3x {
    /// From components.
    #[must_use]
    pub const fn new(x: I16F16, y: I16F16, z: I16F16) -> Self {
        Self { x, y, z }
    }
    /// Rounds each `f32` component (see [`I16F16::from_f32`]).
    #[must_use]
    pub fn from_f32(v: [f32; 3]) -> Self {
        Self::new(
            I16F16::from_f32(v[0]),
            I16F16::from_f32(v[1]),
            I16F16::from_f32(v[2]),
        )
    }
    /// Components as `f32`.
    #[must_use]
    pub fn to_f32(self) -> [f32; 3] {
        [self.x.to_f32(), self.y.to_f32(), self.z.to_f32()]
    }
}

/// Per-ray data for fixed-point mode. Built only by [`crate::Ray`]'s constructors.
#[derive(Clone, Copy, Debug)]
pub struct FixedRay {
    /// Origin, raw Q16.16.
    origin: [i64; 3],
    /// Unit direction, raw Q2.30.
    dir: [i64; 3],
    /// `2^62 / dir` truncated (`i64::MAX` for a zero component).
    recip: [i64; 3],
    /// Origin as seen from the boxes' `lo` planes: one raw unit up, so every box grows by one
    /// unit downwards (and a zero-direction origin on a plane is strictly inside the slab).
    o_lo: [i64; 3],
    /// Origin as seen from the boxes' `hi` planes: one raw unit down.
    o_hi: [i64; 3],
    /// `2^30 / dir` rounded to `f32` (`+inf` for a zero component): the reciprocal the
    /// 4-wide box test reads where it runs in vector lanes (`wide::slab4_fixed`).
    #[cfg(any(
        target_feature = "sse2",
        all(target_arch = "aarch64", target_feature = "neon")
    ))]
    inv_lanes: [f32; 3],
}

fn check_raw(x: i32) -> Result<(), PointError> {
    if x.unsigned_abs() > LIMIT_RAW as u32 {
        Err(PointError::OutOfRange {
            limit: FIXED_COORD_LIMIT,
        })
    } else {
        Ok(())
    }
}

impl FixedRay {
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline)]
    fn new(origin: [I16F16; 3], dir: [i64; 3]) -> Result<Self, RayError> {
        for x in origin {
            check_raw(x.0).map_err(RayError::Origin)?;
        }
        let o = origin.map(|x| x.0 as i64);
        let mut r = Self {
            origin: o,
            dir: [0; 3],
            recip: [0; 3],
            // The box grows by one raw unit on each side, as seen from these origins.
            o_lo: o.map(|x| x + 1),
            o_hi: o.map(|x| x - 1),
            #[cfg(any(
                target_feature = "sse2",
                all(target_arch = "aarch64", target_feature = "neon")
            ))]
            inv_lanes: [0.0; 3],
        };
        r.set_dir(dir);
        Ok(r)
    }

    /// Sets the direction (Q2.30, from [`q30`] or [`q30_from_f32`]) and its reciprocals.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline)]
    fn set_dir(&mut self, dir: [i64; 3]) {
        self.dir = dir;
        self.recip = self
            .dir
            .map(|d| if d == 0 { i64::MAX } else { (1i64 << 62) / d });
        #[cfg(any(
            target_feature = "sse2",
            all(target_arch = "aarch64", target_feature = "neon")
        ))]
        {
            // `d as f32` and the quotient round: two relative errors of 2^-24 at most.
            self.inv_lanes = self.dir.map(|d| {
                if d == 0 {
                    f32::INFINITY
                } else {
                    DIR_ONE as f32 / d as f32
                }
            });
        }
    }

    fn moved(&self, origin: [I16F16; 3]) -> Result<Self, RayError> {
        let mut r = *self;
        for (i, x) in origin.iter().enumerate() {
            check_raw(x.0).map_err(RayError::Origin)?;
            let o = x.0 as i64;
            r.origin[i] = o;
            r.o_lo[i] = o + 1;
            r.o_hi[i] = o - 1;
        }
        Ok(r)
    }

    #[inline(always)]
    fn rel(&self, v: &[I16F16; 3]) -> [i64; 3] {
        [
            v[0].0 as i64 - self.origin[0],
            v[1].0 as i64 - self.origin[1],
            v[2].0 as i64 - self.origin[2],
        ]
    }

    /// `p × dir`; each component `< 2^61`.
    #[inline(always)]
    fn cross_dir(&self, p: &[i64; 3]) -> [i64; 3] {
        let d = &self.dir;
        [
            p[1] * d[2] - p[2] * d[1],
            p[2] * d[0] - p[0] * d[2],
            p[0] * d[1] - p[1] * d[0],
        ]
    }

    /// Exact edge functions (U, V, W) and the vertices relative to the origin.
    #[inline(always)]
    fn edges(&self, v: &[[I16F16; 3]; 3]) -> ([i128; 3], [[i64; 3]; 3]) {
        let (a, b, c) = (self.rel(&v[0]), self.rel(&v[1]), self.rel(&v[2]));
        let (ad, bd, cd) = (self.cross_dir(&a), self.cross_dir(&b), self.cross_dir(&c));
        ([dot(&c, &bd), dot(&a, &cd), dot(&b, &ad)], [a, b, c])
    }
}

#[inline(always)]
fn dot(p: &[i64; 3], q: &[i64; 3]) -> i128 {
    p[0] as i128 * q[0] as i128 + p[1] as i128 * q[1] as i128 + p[2] as i128 * q[2] as i128
}

/// Range check on a raw distance (`i128`) and conversion to `I16F16`.
fn t_in_range(t: i128, t_min: I16F16, t_max: I16F16) -> Option<I16F16> {
    if t >= t_min.0 as i128 && t <= t_max.0 as i128 {
        Some(I16F16(t as i32))
    } else {
        None
    }
}

impl Scalar for I16F16 {
    type Vec3 = Vec3x;

    const ZERO: Self = Self(0);
    const FAR: Self = Self::MAX;
    const NAME: &'static str = "fixed";

    fn to_f32(self) -> f32 {
        I16F16::to_f32(self)
    }
    fn to_f64(self) -> f64 {
        f64::from(self.raw()) / 65536.0
    }
    fn from_f32_saturating(x: f32) -> Self {
        I16F16::from_f32(x)
    }
    fn coord_from_f32(x: f32) -> Result<Self, PointError> {
        if !x.is_finite() {
            return Err(PointError::NonFinite);
        }
        let v = I16F16::from_f32(x);
        check_raw(v.0).map(|()| v)
    }
    fn vec_to_array(v: Vec3x) -> [Self; 3] {
        [v.x, v.y, v.z]
    }
    fn array_to_vec(a: [Self; 3]) -> Vec3x {
        Vec3x::new(a[0], a[1], a[2])
    }
    fn check_point(p: [Self; 3]) -> Result<(), PointError> {
        p.iter().try_for_each(|x| check_raw(x.0))
    }
    fn check_radius(r: Self) -> Result<(), PointError> {
        if r.0 < 0 {
            Err(PointError::NegativeRadius)
        } else {
            check_raw(r.0)
        }
    }
    fn ray_origin(ray: &FixedRay) -> [Self; 3] {
        ray.origin.map(|x| I16F16(x as i32))
    }
    fn ray_dir(ray: &FixedRay) -> [Self; 3] {
        // Q2.30 -> Q16.16, rounded.
        ray.dir.map(|d| I16F16(((d + (1 << 13)) >> 14) as i32))
    }
}

impl Numerics for I16F16 {
    type RayData = FixedRay;
    const LOWEST: Self = I16F16(i32::MIN);

    fn ray_data(origin: [Self; 3], dir: [Self; 3]) -> Result<FixedRay, RayError> {
        Self::check_point(origin).map_err(RayError::Origin)?;
        let unit = super::float::unit_dir_f64([dir[0].0 as f64, dir[1].0 as f64, dir[2].0 as f64])?;
        FixedRay::new(origin, q30(unit))
    }
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline)]
    fn ray_data_from_f32(origin: [f32; 3], dir: [f32; 3]) -> Result<FixedRay, RayError> {
        let mut o = [I16F16::ZERO; 3];
        for i in 0..3 {
            o[i] = Self::coord_from_f32(origin[i]).map_err(RayError::Origin)?;
        }
        FixedRay::new(o, q30_from_f32(dir)?)
    }
    fn ray_moved(ray: &FixedRay, origin: [Self; 3]) -> Result<FixedRay, RayError> {
        ray.moved(origin)
    }
    #[inline]
    fn ray_redirected_f32(ray: &FixedRay, dir: [f32; 3]) -> Result<FixedRay, RayError> {
        let mut r = *ray;
        r.set_dir(q30_from_f32(dir)?);
        Ok(r)
    }

    fn pad_bounds(lo: [Self; 3], hi: [Self; 3]) -> ([Self; 3], [Self; 3]) {
        (lo, hi)
    }

    #[inline(always)]
    fn slab(
        r: &FixedRay,
        lo: &[Self; 3],
        hi: &[Self; 3],
        t_min: Self,
        t_max: Self,
    ) -> Option<Self> {
        let mut t_near = t_min.0 as i64;
        let mut t_far = t_max.0 as i64 + SLAB_PAD;
        for i in 0..3 {
            let a = (((lo[i].0 as i64 - r.o_lo[i]) as i128 * r.recip[i] as i128) >> 32) as i64;
            let b = (((hi[i].0 as i64 - r.o_hi[i]) as i128 * r.recip[i] as i128) >> 32) as i64;
            t_near = t_near.max(a.min(b) - SLAB_PAD);
            t_far = t_far.min(a.max(b) + SLAB_PAD);
        }
        // t_near <= t_far <= t_max + pad, and t_near >= t_min >= 0: fits after the clamp.
        if t_near <= t_far {
            Some(I16F16(t_near.min(i32::MAX as i64) as i32))
        } else {
            None
        }
    }

    #[cfg(any(
        target_feature = "sse2",
        all(target_arch = "aarch64", target_feature = "neon")
    ))]
    #[inline(always)]
    fn slab4(
        r: &FixedRay,
        lo: &[[Self; 4]; 3],
        hi: &[[Self; 4]; 3],
        t_min: Self,
        t_max: Self,
    ) -> (u32, [Self; 4]) {
        let (o_lo, o_hi) = r.raw_shifted_origins();
        let (mask, t) = super::wide::slab4_fixed(
            o_lo,
            o_hi,
            r.inv_lanes,
            &raw_planes(lo),
            &raw_planes(hi),
            t_min.0,
            t_max.0,
        );
        (mask, t.map(I16F16))
    }

    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    #[inline(always)]
    unsafe fn slab8_avx2(
        r: &FixedRay,
        lo: &[[Self; 8]; 3],
        hi: &[[Self; 8]; 3],
        t_min: Self,
        t_max: Self,
    ) -> (u32, [Self; 8]) {
        let (o_lo, o_hi) = r.raw_shifted_origins();
        // SAFETY: the caller guarantees AVX2, the features `slab8_avx2_fixed` enables.
        let (mask, t) = unsafe {
            super::wide::slab8_avx2_fixed(
                o_lo,
                o_hi,
                r.inv_lanes,
                &raw_planes(lo),
                &raw_planes(hi),
                t_min.0,
                t_max.0,
            )
        };
        (mask, t.map(I16F16))
    }

    #[inline(always)]
    fn slab_axis(r: &FixedRay, axis: usize, lo: Self, hi: Self) -> (Self, Self) {
        // The same integer steps as one axis of `slab`, clamped into range (monotone).
        let i = axis.min(2);
        let a = (((lo.0 as i64 - r.o_lo[i]) as i128 * r.recip[i] as i128) >> 32) as i64;
        let b = (((hi.0 as i64 - r.o_hi[i]) as i128 * r.recip[i] as i128) >> 32) as i64;
        let clamp = |x: i64| I16F16(x.clamp(i32::MIN as i64, i32::MAX as i64) as i32);
        (clamp(a.min(b) - SLAB_PAD), clamp(a.max(b) + SLAB_PAD))
    }

    #[inline(always)]
    fn axis_negative(r: &FixedRay, axis: usize) -> bool {
        r.dir[axis.min(2)] < 0
    }

    #[inline(always)]
    fn widen(t: Self) -> Self {
        I16F16(t.0.saturating_add(SLAB_PAD as i32))
    }

    #[inline(always)]
    fn order_bits(t: Self) -> u32 {
        t.0 as u32
    }

    #[inline(always)]
    fn triangle_t(r: &FixedRay, v: &[[Self; 3]; 3], t_min: Self, t_max: Self) -> Option<Self> {
        let ([eu, ev, ew], [a, b, c]) = r.edges(v);
        if (eu < 0 || ev < 0 || ew < 0) && (eu > 0 || ev > 0 || ew > 0) {
            return None;
        }
        let mut det = eu + ev + ew;
        if det == 0 {
            return None;
        }
        // T = A'·(C'×B'): t = T / det in units of the Q2.30 direction.
        let cb = [
            c[1] * b[2] - c[2] * b[1],
            c[2] * b[0] - c[0] * b[2],
            c[0] * b[1] - c[1] * b[0],
        ];
        let mut tt = dot(&a, &cb);
        if det < 0 {
            det = -det;
            tt = -tt;
        }
        if tt < 0 {
            return None;
        }
        // Raw Q16.16 t = T·2^48-scale / det·2^62-scale · 2^16 = T·2^30 / det; T < 2^93.
        // det > 0 here; the checked division only keeps a panic path out of the code.
        t_in_range((tt << 30).checked_div(det)?, t_min, t_max)
    }

    fn triangle_uv(r: &FixedRay, v: &[[Self; 3]; 3]) -> (Self, Self) {
        let ([eu, ev, ew], _) = r.edges(v);
        let det = eu + ev + ew;
        if det == 0 {
            return (Self::ZERO, Self::ZERO);
        }
        let q = |e: i128| {
            let (n, d) = if det < 0 { (-e, -det) } else { (e, det) };
            I16F16(((n << 16).checked_div(d).unwrap_or(0)).clamp(0, ONE_RAW as i128) as i32)
        };
        (q(ev), q(ew))
    }

    fn sphere_t(
        r: &FixedRay,
        center: &[Self; 3],
        radius: Self,
        t_min: Self,
        t_max: Self,
    ) -> Option<Self> {
        // |L + t·D|² = R² with L = O - C (scale 2^16) and D (scale 2^30):
        // a t² + 2 b t + c = 0 with a = D·D (2^60), b = L·D (2^46), c = L·L - R² (2^32).
        let l = [
            r.origin[0] - center[0].0 as i64,
            r.origin[1] - center[1].0 as i64,
            r.origin[2] - center[2].0 as i64,
        ];
        let a = dot(&r.dir, &r.dir);
        let b = dot(&l, &r.dir);
        let c = dot(&l, &l) - radius.0 as i128 * radius.0 as i128;
        let disc = b * b - a * c; // scale 2^92, < 2^125
        if disc < 0 || a == 0 {
            return None;
        }
        let s = disc.unsigned_abs().isqrt() as i128; // scale 2^46
                                                     // t (raw Q16.16) = (-b ∓ s) · 2^30 / a, floored.
                                                     // a > 0 here; the checked divisions only keep a panic path out of the code.
        let near = ((-b - s) << 30).checked_div_euclid(a)?;
        let far = ((-b + s) << 30).checked_div_euclid(a)?;
        t_in_range(near, t_min, t_max).or_else(|| t_in_range(far, t_min, t_max))
    }

    fn sphere_bounds(center: &[Self; 3], radius: Self) -> ([Self; 3], [Self; 3]) {
        (center.map(|c| c - radius), center.map(|c| c + radius))
    }
}

/// A wide node's planes as raw Q16.16 integers, for the lane box tests.
#[cfg(any(
    target_feature = "sse2",
    all(target_arch = "aarch64", target_feature = "neon")
))]
#[inline(always)]
fn raw_planes<const N: usize>(planes: &[[I16F16; N]; 3]) -> [[i32; N]; 3] {
    planes.map(|axis| axis.map(|x| x.0))
}

#[cfg(any(
    target_feature = "sse2",
    all(target_arch = "aarch64", target_feature = "neon")
))]
impl FixedRay {
    /// The shifted origins as raw `i32` (`|origin| <= 2^29`, so the shifted ones fit), for
    /// the lane box tests.
    #[inline(always)]
    fn raw_shifted_origins(&self) -> ([i32; 3], [i32; 3]) {
        (self.o_lo.map(|x| x as i32), self.o_hi.map(|x| x as i32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_rounds_and_saturates() {
        let f = I16F16::from_f32;
        assert_eq!(f(1.5) * f(2.0), f(3.0));
        assert_eq!(f(1.0) / f(3.0), I16F16(21845));
        assert_eq!(I16F16::MAX + I16F16::ONE, I16F16::MAX);
        assert_eq!(I16F16::MIN - I16F16::ONE, I16F16::MIN);
        assert_eq!(-I16F16::MIN, I16F16::MAX);
        assert_eq!(f(20000.0) * f(20000.0), I16F16::MAX);
        assert_eq!(f(1.0) / I16F16::ZERO, I16F16::MAX);
        assert_eq!(f(f32::NAN), I16F16::ZERO);
        assert_eq!(f(-2.5).to_f32(), -2.5);
    }

    #[test]
    fn unit_directions_use_thirty_fraction_bits() {
        let r = FixedRay::new([I16F16::ZERO; 3], q30([0.6, 0.8, 0.0])).unwrap();
        assert_eq!(r.dir, [644_245_094, 858_993_459, 0]);
        assert_eq!(r.recip[2], i64::MAX);
    }

    use crate::scalar::xorshift as next;

    /// `q30_from_f32` returns `q30(unit_dir_from_f32(d))`, bit for bit, and the same errors:
    /// on unit vectors rounded from `f64` (as ray generators give them), on unnormalised ones
    /// over the whole `f32` range (subnormal, huge, zero components), and on zero and
    /// non-finite ones. The direct path must serve nearly all and the scaled fallback some.
    #[test]
    fn direct_q30_is_the_scaled_normalisation() {
        // The scaled path's answer, after checking that `q30_from_f32` gives it.
        let check = |d: [f32; 3]| {
            let want = super::super::float::unit_dir_from_f32(d).map(q30);
            assert_eq!(
                q30_from_f32(d),
                want,
                "{d:?} bits {:x?}",
                d.map(f32::to_bits)
            );
            want
        };
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let (mut direct, mut total) = (0usize, 0usize);
        for i in 0..3_000_000u32 {
            let mut component = || {
                let bits = next(&mut state);
                let x = (bits >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
                match i % 4 {
                    0 | 1 => x as f32,
                    2 => (x * libm::exp2(((bits & 0xff) as f64) - 150.0)) as f32,
                    _ if bits & 7 == 0 => 0.0,
                    _ => f32::from_bits(bits as u32 & 0x807f_ffff), // subnormal or zero
                }
            };
            let mut d = [component(), component(), component()];
            if i % 4 == 0 {
                // Unit vectors rounded from f64, the common case.
                let w = d.map(f64::from);
                let n = crate::scalar::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
                d = w.map(|x| (x / n) as f32);
            }
            if check(d).is_ok() {
                total += 1;
                direct += usize::from(direct_q30(d).is_some());
            }
        }
        // Directions whose x lies within about 2^-30 raw units of a tie, the rounding's hard
        // cases: `(x, y, z)` with `x/y` about 2^-20 puts x near 2^10 raw units; x is stepped
        // until its fraction is just above one half, then z, which shrinks it by about
        // `x·z²/2y²`, is chosen to bring it onto the tie, and its neighbours are tried.
        let raw_x = |d: [f32; 3]| {
            super::super::float::unit_dir_direct_f32(d).map_or(0.0, |u| u[0] * DIR_ONE)
        };
        let fraction = |v: f64| v - libm::floor(v);
        let mut near = 0usize;
        for _ in 0..2000 {
            let y = (1_048_576.0 * (1.0 + (next(&mut state) >> 40) as f64 / (1u64 << 24) as f64))
                as f32;
            let mut x = 1.0 + (next(&mut state) >> 41) as f32 / (1u64 << 23) as f32;
            while !(0.5..0.5 + 1.0 / 4096.0).contains(&fraction(raw_x([x, y, 0.0]))) && x < 4.0 {
                x = f32::from_bits(x.to_bits() + 1);
            }
            let v = raw_x([x, y, 0.0]);
            let z0 = (f64::from(y) * crate::scalar::sqrt(2.0 * (fraction(v) - 0.5) / v)) as f32;
            for step in -40i32..40 {
                let d = [x, y, f32::from_bits(z0.to_bits().wrapping_add_signed(step))];
                if libm::fabs(fraction(raw_x(d)) - 0.5) < 1.0 / 1_048_576.0 {
                    near += 1;
                }
                let _ = check(d);
            }
        }
        assert!(near > 10_000, "{near} directions within 2^-20 of a tie");
        for d in [
            [0.0; 3],
            [f32::NAN, 1.0, 0.0],
            [0.0, f32::INFINITY, 1.0],
            [-0.0, 0.0, -0.0],
        ] {
            assert!(check(d).is_err(), "{d:?}");
        }
        assert!(
            direct > total - total / 1000 && direct < total,
            "{direct} of {total}"
        );
    }

    #[test]
    fn rounding_matches_libm_round() {
        let edges = [
            0.5,
            0.499_999_999_999_999_94,
            0.500_000_000_000_000_1,
            1.5,
            2.5,
            -2.5,
            4_503_599_627_370_495.5,
            4_503_599_627_370_496.0,
            9_007_199_254_740_993.0,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            0.0,
            -0.0,
        ];
        let check = |v: f64| {
            for v in [v, -v] {
                let (wide, narrow) = (libm::round(v) as i64, libm::round(v) as i32);
                assert_eq!(to_round(v) as i64, wide, "{v:e} ({:#x})", v.to_bits());
                assert_eq!(to_round(v) as i32, narrow, "{v:e} ({:#x})", v.to_bits());
            }
        };
        edges.into_iter().for_each(check);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..200_000 {
            let bits = next(&mut state);
            // Arbitrary bit patterns, and values a few ulps from halves of integers below 2^31
            // and from one half.
            check(f64::from_bits(bits));
            let ulps = (bits & 7) as i64 - 3;
            let near = |x: f64| f64::from_bits((x.to_bits() as i64 + ulps) as u64);
            check(near((bits >> 33) as f64 + 0.5));
            check(near(0.5));
        }
    }

    /// Whether the ray meets the box `[lo - grow, hi + grow]` at a `t` (raw units, real) in
    /// `[t_lo, t_hi]`, and if so the least such `t` as a fraction `(num, den)`; exact, in
    /// `i128`.
    fn meets(
        r: &FixedRay,
        lo: [i64; 3],
        hi: [i64; 3],
        grow: i64,
        t_lo: i64,
        t_hi: i64,
    ) -> Option<(i128, i128)> {
        // Fractions num/den with den > 0; `first` is the running lower end, `last` the upper.
        let (mut first, mut last) = ((t_lo as i128, 1i128), (t_hi as i128, 1i128));
        let less = |a: (i128, i128), b: (i128, i128)| a.0 * b.1 < b.0 * a.1;
        for k in 0..3 {
            let (l, h, o, d) = (lo[k] - grow, hi[k] + grow, r.origin[k], r.dir[k]);
            if d == 0 {
                if o < l || o > h {
                    return None;
                }
                continue;
            }
            // t = (plane - o)·2^30 / d.
            let den = d.unsigned_abs() as i128;
            let sign = d.signum() as i128;
            let ta = ((l - o) as i128 * (1 << 30) * sign, den);
            let tb = ((h - o) as i128 * (1 << 30) * sign, den);
            let (near, far) = if less(tb, ta) { (tb, ta) } else { (ta, tb) };
            if less(first, near) {
                first = near;
            }
            if less(far, last) {
                last = far;
            }
        }
        (!less(last, first)).then_some(first)
    }

    /// The float-lane box test of the 4-wide BVH accepts every box the ray meets within
    /// `[t_min, t_max + 1]` (where a hit reported at `t_max` can lie), with an entry no later
    /// than the exact one, and accepts no box it misses by more than its margins.
    #[cfg(any(
        target_feature = "sse2",
        all(target_arch = "aarch64", target_feature = "neon")
    ))]
    #[test]
    fn slab4_is_conservative_and_tight() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let (mut met, mut missed) = (0, 0);
        for case in 0..50_000 {
            let coord = |state: &mut u64| {
                let bits = next(state);
                let scale = 1i64 << (4 + bits % 26); // raw 2^4 .. 2^29
                (((bits >> 8) as i64 % (2 * scale + 1)) - scale).clamp(-(1 << 29), 1 << 29)
            };
            let origin = [0; 3].map(|_| I16F16(coord(&mut state) as i32));
            let mut d = [0.0f64; 3];
            for x in &mut d {
                let bits = next(&mut state);
                *x = match bits % 8 {
                    0 => 0.0,
                    1 => (bits >> 12) as f64 * 1e-30, // tiny components: huge reciprocals
                    _ => (bits >> 11) as f64 / (1u64 << 53) as f64 - 0.5,
                };
            }
            let Ok(unit) = crate::scalar::float::unit_dir_f64(d) else {
                continue;
            };
            let r = FixedRay::new(origin, q30(unit)).expect("origin in range");
            let (mut lo, mut hi) = ([[I16F16(0); 4]; 3], [[I16F16(0); 4]; 3]);
            let mut boxes = [([0i64; 3], [0i64; 3]); 4];
            for (b, (bl, bh)) in boxes.iter_mut().enumerate() {
                // Half the boxes have planes near a point of the ray (which grazes or enters
                // them), the others near the origin or anywhere; some are flat.
                let along = next(&mut state);
                let t_on = (next(&mut state) >> (34 + along % 30)) as i128;
                for k in 0..3 {
                    let bits = next(&mut state);
                    let on_ray = r.origin[k] + ((t_on * r.dir[k] as i128) >> 30) as i64;
                    let pick = |state: &mut u64, side: i64| match (along % 2, bits % 4) {
                        (0, _) => on_ray + side * ((next(state) % 5) as i64 - 1),
                        (_, 0) => r.origin[k] + (next(state) % 5) as i64 - 2,
                        _ => coord(state),
                    };
                    let x = pick(&mut state, -1);
                    let y = if bits % 7 == 0 {
                        x
                    } else {
                        pick(&mut state, 1)
                    };
                    (bl[k], bh[k]) = (x.min(y), x.max(y));
                    lo[k][b] = I16F16(bl[k] as i32);
                    hi[k][b] = I16F16(bh[k] as i32);
                }
            }
            let t_pick = |bits: u64| match bits % 4 {
                0 => 0,
                1 | 2 => i32::MAX,
                _ => (bits >> (34 + (bits >> 8) % 30)) as i32,
            };
            let (a, b) = (t_pick(next(&mut state)), t_pick(next(&mut state)));
            let (t_min, t_max) = (a.min(b), a.max(b));
            let (mask, t) = I16F16::slab4(&r, &lo, &hi, I16F16(t_min), I16F16(t_max));
            for (i, &(bl, bh)) in boxes.iter().enumerate() {
                let accepted = mask & (1 << i) != 0;
                let (t_min, t_max) = (i64::from(t_min), i64::from(t_max));
                if let Some((num, den)) = meets(&r, bl, bh, 0, t_min, t_max + 1) {
                    met += 1;
                    assert!(accepted, "case {case} box {i}: missed");
                    assert!(
                        i128::from(t[i].0) * den <= num,
                        "case {case} box {i}: entry {} after {num}/{den}",
                        t[i].0
                    );
                } else {
                    missed += 1;
                }
                if accepted {
                    // Margins: a relative 2^-18 of the distances involved, plus two raw units.
                    let reach = (0..3)
                        .flat_map(|k| [bl[k], bh[k]].map(|p| (p - r.origin[k]).abs()))
                        .max()
                        .unwrap_or(0);
                    let grow = 3 + (reach >> 18);
                    let slack = |t: i64| (t >> 18) + 1;
                    let near = meets(
                        &r,
                        bl,
                        bh,
                        grow,
                        t_min - slack(t_min),
                        t_max + 3 + slack(t_max),
                    );
                    assert!(
                        near.is_some(),
                        "case {case} box {i}: accepted, far off the ray"
                    );
                }
            }
        }
        assert!(met > 10_000 && missed > 10_000, "{met} {missed}");
    }
}
