//! Motion: an object moving by `motion` over the shutter sits at `+ s·motion` at shutter time
//! `s`. A ray at time `s` meets it by moving the ray into the object's frame: origin minus the
//! displacement `d(s) = round(s·motion)` (rounded once to the mode; in fixed point the shift is
//! exact). Before that, the unshifted ray must enter the object's swept box, the union of its
//! box at `s = 0` and at `s = 1`, padded by `2^-20` of the motion's largest component (in `f32`,
//! this covers the rounding of the shifted origin; the slab test's own margin covers the
//! origin's share).

use crate::geom::{Aabb, Ray};
use crate::scalar::Scalar;

/// `+ d` in the mode, rounded once.
pub(super) fn shifted<S: Scalar>(p: [S; 3], d: [f64; 3], sign: f64) -> [S; 3] {
    S::point_from_f64(core::array::from_fn(|k| p[k].to_f64() + sign * d[k]))
}

/// `ray` moved into the frame of an object moving by `motion`, at shutter time `time`: origin
/// minus the displacement. `None` if the moved origin leaves the mode's range.
pub(super) fn moved_into_frame<S: Scalar>(
    motion: [f32; 3],
    ray: &Ray<S>,
    time: f32,
) -> Option<Ray<S>> {
    let origin = shifted(
        S::vec_to_array(ray.origin()),
        displacement::<S>(motion, time),
        -1.0,
    );
    ray.moved(origin).ok()
}

/// `round(time·motion)` in the mode, as `f64` (exact).
pub(super) fn displacement<S: Scalar>(m: [f32; 3], time: f32) -> [f64; 3] {
    let d = S::point_from_f64(m.map(|x| f64::from(x) * f64::from(time)));
    d.map(S::to_f64)
}

/// The box over the whole shutter, padded as the module docs state.
pub(super) fn swept_box<S: Scalar>(b: &Aabb<S>, m: [f32; 3]) -> Aabb<S> {
    let d = displacement::<S>(m, 1.0);
    let pad = m
        .iter()
        .fold(0.0f64, |a, x| libm::fmax(a, libm::fabs(f64::from(*x))))
        / 1_048_576.0;
    let lo: [f64; 3] = core::array::from_fn(|k| {
        let x = b.lo[k].to_f64();
        libm::fmin(x, x + d[k]) - pad
    });
    let hi: [f64; 3] = core::array::from_fn(|k| {
        let x = b.hi[k].to_f64();
        libm::fmax(x, x + d[k]) + pad
    });
    // Round outward: one unit past the nearest value.
    let lo = S::point_from_f64(lo).map(|x| S::step(x, false));
    let hi = S::point_from_f64(hi).map(|x| S::step(x, true));
    let (lo, hi) = S::pad_bounds(lo, hi);
    Aabb::new(lo, hi)
}
