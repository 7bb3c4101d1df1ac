//! Spawning secondary rays (reflection, shadow) from a hit without re-hitting its own surface.
//!
//! A hit point carries rounding error, and a new ray started exactly there may hit the same
//! triangle again at `t ≈ 0` ("self-intersection", shadow acne). The rule here follows pbrt-v4
//! (`OffsetRayOrigin`, *Physically Based Rendering* 4th ed. §6.8.6): move the origin off the
//! triangle's plane, along its geometric normal, to the side the new direction points to, by
//! more than the error of the hit point and of the triangle test. It is written once for both
//! number modes, generic over [`Scalar`]; what differs per mode (rounding, the side test, unit
//! steps) is the sealed `Spawn` supertrait, implemented below. It uses no allocation.
//!
//! # The rule and its bound
//!
//! 1. The hit point is rebuilt from the barycentrics, `p = v0 + u·(v1−v0) + v·(v2−v0)`, in
//!    `f64`. Barycentric error moves `p` *within* the plane (any affine combination of the
//!    vertices lies on it), so `p`'s distance from the plane is only the `f64` rounding,
//!    below `2^-50·M`, where `M` is the largest coordinate magnitude of the triangle and `p`.
//! 2. The origin is `p + s·δ·n̂`, `n̂` the unit geometric normal, `s = sign(n̂·dir)`, and
//!    - `f32` mode: `δ = 2^-16·M` ([`F32_SPAWN_OFFSET`]). Rounding the origin to `f32` moves it
//!      by at most `√3·2^-24·M`, so it ends at least `(2^-16 − 2^-22)·M` from the plane. The
//!      kernel's `f32` triangle test displaces the plane (as seen by the ray) by the rounding of
//!      `v − o` and of the shear, at most about `8·2^-24·M = 2^-21·M` at points of the
//!      triangle: the offset is more than 30 times that, so the computed `t` of the triangle's
//!      plane stays negative and the triangle is not hit (for `|n̂·dir| ≥ 2^-20`: closer to
//!      tangent the rounding of the direction itself may flip which side it points to).
//!    - fixed-point mode: `δ = 2` raw units (`2^-15`), the origin rounded to Q16.16. The fixed
//!      triangle test is exact (integer edge functions and an exact sign of `t`), so all that is
//!      needed is an origin strictly on `dir`'s side of the exact plane.
//! 3. Both modes then check the side (`n·(o − v0)`, exactly in `i128` for fixed point, in `f64`
//!    for `f32`, where its error is below `2^-45·M`, far under the offset) and step the origin
//!    one unit (ulp or raw) along the normal's dominant axis until it is strictly on the right
//!    side (at most [`MAX_NUDGES`] steps; not needed in practice, it guards the rounding).
//!
//! Shadow rays: [`spawn_shadow_ray`] aims at a target point and stops short of it by
//! [`SHADOW_SHORTEN`] of the distance (and at least one raw unit in fixed point). When the target
//! lies on a surface, offset it first with [`offset_origin`] toward the shading point's *offset*
//! origin (`offset_origin` of the shading hit), so the target's own surface lies beyond `t_max`
//! by at least its offset. Not toward the raw hit point: a hit on an edge shared with the
//! target's triangle lies on the target's plane, and the side would be a coin toss.
//!
//! The stress suite (`kernel/tests/stress.rs`) counts self-hits over millions of spawned rays at
//! scales 1e-4 to 1e4 and in the fixed-point range; the fuzz target `accel_equivalence` calls
//! these functions on arbitrary scenes.

use super::{Hit, Ray, Triangle};
use crate::scalar::sealed::Spawn;
use crate::scalar::{RayError, Scalar, I16F16};

/// Relative offset of the `f32` rule: the origin moves `2^-16·M` off the plane.
pub const F32_SPAWN_OFFSET: f64 = 1.0 / 65536.0;
/// Offset of the fixed-point rule, in raw Q16.16 units.
pub const FIXED_SPAWN_OFFSET_RAW: i32 = 2;
/// Shadow rays stop this fraction of the distance short of their target.
pub const SHADOW_SHORTEN: f64 = 1.0 / 1_048_576.0;
/// Most unit steps the side check may take.
pub const MAX_NUDGES: u32 = 64;

impl Spawn for f32 {
    fn point_from_f64(p: [f64; 3]) -> [f32; 3] {
        p.map(|x| x as f32)
    }
    fn spawn_offset(m: f64) -> f64 {
        m * F32_SPAWN_OFFSET + f64::from(f32::MIN_POSITIVE)
    }
    fn side(v: &[[f32; 3]; 3], p: &[f32; 3]) -> i32 {
        let f = |a: &[f32; 3]| a.map(f64::from);
        let n = normal_f64(&[f(&v[0]), f(&v[1]), f(&v[2])]);
        let d = sub(&f(p), &f(&v[0]));
        sign(dot(&n, &d))
    }
    fn step(x: f32, up: bool) -> f32 {
        if !x.is_finite() {
            return x;
        }
        if x == 0.0 {
            let tiny = f32::from_bits(1);
            return if up { tiny } else { -tiny };
        }
        let bits = x.to_bits();
        f32::from_bits(if (x > 0.0) == up { bits + 1 } else { bits - 1 })
    }
    fn t_down(t: f64, extra: u32) -> f32 {
        let mut r = t as f32;
        if f64::from(r) > t {
            r = Self::step(r, false);
        }
        for _ in 0..extra {
            r = Self::step(r, false);
        }
        if r > 0.0 {
            r
        } else {
            0.0
        }
    }
}

impl Spawn for I16F16 {
    fn point_from_f64(p: [f64; 3]) -> [I16F16; 3] {
        p.map(|x| {
            let r = libm::round(x * 65536.0);
            // `as` saturates (and maps NaN to 0).
            I16F16::from_raw(r as i32)
        })
    }
    fn spawn_offset(_m: f64) -> f64 {
        f64::from(FIXED_SPAWN_OFFSET_RAW) / 65536.0
    }
    fn side(v: &[[I16F16; 3]; 3], p: &[I16F16; 3]) -> i32 {
        let r = |a: &[I16F16; 3]| a.map(|x| i128::from(x.raw()));
        let (a, b, c, q) = (r(&v[0]), r(&v[1]), r(&v[2]), r(p));
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        // |e| < 2^32, |n| < 2^65, |q − a| < 2^32: the dot product stays below 2^99.
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let s = n[0] * (q[0] - a[0]) + n[1] * (q[1] - a[1]) + n[2] * (q[2] - a[2]);
        match s {
            0 => 0,
            s if s > 0 => 1,
            _ => -1,
        }
    }
    fn step(x: I16F16, up: bool) -> I16F16 {
        I16F16::from_raw(if up {
            x.raw().saturating_add(1)
        } else {
            x.raw().saturating_sub(1)
        })
    }
    fn t_down(t: f64, extra: u32) -> I16F16 {
        let raw = libm::floor(t * 65536.0) - f64::from(extra);
        I16F16::from_raw(if raw > 0.0 { raw as i32 } else { 0 })
    }
}

pub(crate) fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sign(x: f64) -> i32 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

pub(crate) fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `(v1 − v0) × (v2 − v0)`.
fn normal_f64(v: &[[f64; 3]; 3]) -> [f64; 3] {
    cross(&sub(&v[1], &v[0]), &sub(&v[2], &v[0]))
}

/// `v / |v|`, scaled first so tiny and huge vectors normalise; `None` for zero or non-finite.
pub(crate) fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let m = libm::fmax(
        libm::fabs(v[0]),
        libm::fmax(libm::fabs(v[1]), libm::fabs(v[2])),
    );
    if !(m > 0.0 && m.is_finite()) {
        return None;
    }
    let s = v.map(|x| x / m);
    let l = crate::scalar::sqrt(dot(&s, &s));
    Some(s.map(|x| x / l))
}

fn max_abs(m: f64, p: &[f64; 3]) -> f64 {
    libm::fmax(
        m,
        libm::fmax(
            libm::fabs(p[0]),
            libm::fmax(libm::fabs(p[1]), libm::fabs(p[2])),
        ),
    )
}

/// A ray origin for leaving triangle `tri` at barycentrics `(u, v)` in direction `toward`
/// (any length): off the triangle's plane on `toward`'s side, by the bound in the
/// [module docs](self). For a degenerate triangle (no normal) the point is moved along
/// `toward` instead.
#[must_use]
pub fn offset_origin<S: Scalar>(tri: &Triangle<S>, u: S, v: S, toward: S::Vec3) -> [S; 3] {
    let vf = tri.v.map(|p| p.map(S::to_f64));
    let (uf, vv) = (u.to_f64(), v.to_f64());
    let e1 = sub(&vf[1], &vf[0]);
    let e2 = sub(&vf[2], &vf[0]);
    let p: [f64; 3] = core::array::from_fn(|k| vf[0][k] + uf * e1[k] + vv * e2[k]);
    let d = S::vec_to_array(toward).map(S::to_f64);
    let m = vf.iter().fold(max_abs(0.0, &p), max_abs);
    let delta = S::spawn_offset(m);

    let Some(n) = unit(normal_f64(&vf)) else {
        // Degenerate triangle (never hit by the kernel): step along the new direction.
        let dir = unit(d).unwrap_or([0.0; 3]);
        return S::point_from_f64(core::array::from_fn(|k| p[k] + delta * dir[k]));
    };
    let s = if dot(&n, &d) < 0.0 { -1.0 } else { 1.0 };
    let mut o = S::point_from_f64(core::array::from_fn(|k| p[k] + s * delta * n[k]));

    // Make sure the rounded origin is strictly on the chosen side (exact in fixed point).
    let want = if s > 0.0 { 1 } else { -1 };
    let axis = {
        let a = n.map(libm::fabs);
        // Ties to the first axis. Written with `<` alone: one kind of `f64` comparison links
        // one soft-float routine on cores without a double FPU (`n` is finite).
        if a[0] < a[1] || a[0] < a[2] {
            if a[1] < a[2] {
                2
            } else {
                1
            }
        } else {
            0
        }
    };
    let up = (n[axis] > 0.0) == (s > 0.0);
    for _ in 0..MAX_NUDGES {
        if S::side(&tri.v, &o) == want {
            break;
        }
        o[axis] = S::step(o[axis], up);
    }
    o
}

/// A ray leaving `hit` (on triangle `tri`, which the hit's `prim` names) in direction `dir`:
/// origin from [`offset_origin`], interval `[0, S::FAR]`. `ray` is the ray that made the hit
/// (used for nothing but documenting the call site today; the hit point comes from the
/// barycentrics, whose error lies within the plane).
///
/// # Errors
/// As [`Ray::new`] (zero or non-finite `dir`, or an origin pushed out of range).
pub fn spawn_ray<S: Scalar>(
    ray: &Ray<S>,
    hit: &Hit<S>,
    tri: &Triangle<S>,
    dir: S::Vec3,
) -> Result<Ray<S>, RayError> {
    let _ = ray;
    let (u, v) = (hit.u, hit.v);
    let o = offset_origin(tri, u, v, dir);
    Ray::new(S::array_to_vec(o), dir)
}

/// A shadow ray from `hit` toward `target`: origin from [`offset_origin`] (toward the target),
/// `t_max` = distance to `target` shortened by [`SHADOW_SHORTEN`] and one unit. If `target` is
/// on a surface, pass it through [`offset_origin`] first (toward the shading point).
///
/// # Errors
/// As [`Ray::new`]; [`RayError::ZeroDirection`] if the origin and the target coincide.
pub fn spawn_shadow_ray<S: Scalar>(
    ray: &Ray<S>,
    hit: &Hit<S>,
    tri: &Triangle<S>,
    target: [S; 3],
) -> Result<Ray<S>, RayError> {
    let _ = ray;
    let (u, v) = (hit.u, hit.v);
    let vf = tri.v.map(|p| p.map(S::to_f64));
    let p: [f64; 3] = core::array::from_fn(|k| {
        vf[0][k] + u.to_f64() * (vf[1][k] - vf[0][k]) + v.to_f64() * (vf[2][k] - vf[0][k])
    });
    let tf = target.map(S::to_f64);
    let toward = S::point_from_f64(sub(&tf, &p));
    let o = offset_origin(tri, u, v, S::array_to_vec(toward));
    let d = sub(&tf, &o.map(S::to_f64));
    let len = crate::scalar::sqrt(dot(&d, &d));
    let dir = S::point_from_f64(d);
    let r = if dir.iter().all(|&x| x == S::ZERO) {
        // The offset vector is below the mode's resolution: keep its direction in f32.
        let df = d.map(|x| x as f32);
        let of = o.map(|x| S::to_f64(x) as f32);
        Ray::from_f32(of, df, 0.0, f32::INFINITY)?
    } else {
        Ray::new(S::array_to_vec(o), S::array_to_vec(dir))?
    };
    r.with_interval(S::ZERO, shadow_t_max::<S>(len))
}

/// The shadow-ray `t_max` rule for a target at distance `len`: `len·(1 − SHADOW_SHORTEN)`
/// rounded down, minus one unit (ulp or raw).
#[must_use]
pub fn shadow_t_max<S: Scalar>(len: f64) -> S {
    S::t_down(len * (1.0 - SHADOW_SHORTEN), 1)
}
