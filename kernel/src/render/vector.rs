//! Vector lengths with the kernel's square root (`vsqrt.f32` on cores with an FPU, an integer
//! root on the others), in place of glam's, which calls `libm`'s routine on every target.
//! Same formulas as glam's, and every square root involved is correctly rounded, so the bits
//! are the same as glam's on every platform.

use crate::scalar::sqrtf;
use glam::Vec3;

/// `|v|`.
#[inline]
pub(crate) fn length(v: Vec3) -> f32 {
    sqrtf(v.dot(v))
}

/// `v / |v|`, or zero when `|v|` is zero, not finite or its reciprocal is not.
#[inline]
pub(crate) fn normalize_or_zero(v: Vec3) -> Vec3 {
    let rcp = 1.0 / length(v);
    if rcp.is_finite() && rcp > 0.0 {
        v * rcp
    } else {
        Vec3::ZERO
    }
}
