use super::{Accel, Counters, Nearest};
use crate::geom::{closer, Barycentrics, Primitive, Ray};
use crate::scalar::Scalar;
use core::marker::PhantomData;

/// Brute force: tests every primitive. The reference the other accelerators must equal.
#[derive(Clone, Copy, Debug)]
pub struct Linear<'a, S: Scalar, P: Primitive<S>> {
    prims: &'a [P],
    _scalar: PhantomData<S>,
}

impl<'a, S: Scalar, P: Primitive<S>> Linear<'a, S, P> {
    /// Wraps the primitives; nothing is built.
    pub const fn new(prims: &'a [P]) -> Self {
        Self {
            prims,
            _scalar: PhantomData,
        }
    }
}

impl<S: Scalar, P: Primitive<S>> Accel<S> for Linear<'_, S, P> {
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>> {
        let (t_min, mut best_t) = (ray.t_min(), ray.t_max());
        let mut best: Option<u32> = None;
        for (id, prim) in (0u32..).zip(self.prims) {
            stats.prim();
            if let Some(t) = prim.hit_t(ray.data(), t_min, best_t) {
                if best.is_none_or(|b| closer(t, id, best_t, b)) {
                    best_t = t;
                    best = Some(id);
                }
            }
        }
        best.map(|prim| Nearest {
            t: best_t,
            prim,
            slot: prim as usize,
        })
    }

    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> Barycentrics<S> {
        found.barycentrics_in(self.prims, ray)
    }

    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        self.prims.iter().any(|p| {
            stats.prim();
            p.hit_t(ray.data(), ray.t_min(), ray.t_max()).is_some()
        })
    }
}
