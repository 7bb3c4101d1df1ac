//! Stack-based traversal, near child first. One routine serves closest hit and any hit.

use super::{Bvh, Node, MAX_DEPTH};
use crate::accel::{Accel, Counters, Nearest};
use crate::geom::{closer, Primitive, Ray};
use crate::scalar::Scalar;

impl<S: Scalar, P: Primitive<S>> Bvh<'_, S, P> {
    /// Walks the tree. With `ANY`, returns at the first hit in range; otherwise finds the
    /// closest under [`closer`]. Returns (t, prim id, index into `prims`) of the hit;
    /// `prim id == u32::MAX` for none.
    ///
    /// Not inlined: every caller (renderer, host, benchmarks) runs the same machine code, so
    /// their timings differ only by what they do around the walk.
    #[inline(never)]
    fn traverse<const ANY: bool, C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> (S, u32, usize) {
        let rd = ray.data();
        let t_min = ray.t_min();
        let mut best_t = ray.t_max();
        let mut best_prim = u32::MAX;
        let mut best_at = 0usize;
        let Some(root) = self.nodes.first() else {
            return (best_t, best_prim, best_at);
        };
        stats.node();
        if S::slab(rd, &root.lo, &root.hi, t_min, best_t).is_none() {
            return (best_t, best_prim, best_at);
        }
        // Each level below the root pushes at most one entry, and leaves are at most
        // MAX_DEPTH deep, so the stack cannot overflow. `heapless::Vec` leaves its storage
        // uninitialised: a zeroed array cost a 512-byte memset per ray.
        let mut stack: heapless::Vec<(u32, S), MAX_DEPTH> = heapless::Vec::new();
        let mut node: &Node<S> = root;
        'walk: loop {
            if node.count > 0 {
                let first = node.first as usize;
                let ids = self
                    .prim_ids
                    .get(first..first + node.count as usize)
                    .unwrap_or_default();
                for (slot, &id) in (first..).zip(ids) {
                    let at = if self.leaf_order { slot } else { id as usize };
                    let Some(prim) = self.prims.get(at) else {
                        continue;
                    };
                    stats.prim();
                    if let Some(t) = prim.hit_t(rd, t_min, best_t) {
                        if ANY {
                            return (t, id, at);
                        }
                        if closer(t, id, best_t, best_prim) {
                            best_t = t;
                            best_prim = id;
                            best_at = at;
                        }
                    }
                }
            } else {
                let l = node.first as usize;
                if let Some([a, b]) = self.nodes.get(l..l + 2) {
                    stats.node();
                    stats.node();
                    let [ta, tb] = S::slab_pair(rd, (&a.lo, &a.hi), (&b.lo, &b.hi), t_min, best_t);
                    match (ta, tb) {
                        (Some(ta), Some(tb)) => {
                            let (near, far, t_far) =
                                if tb < ta { (b, l, ta) } else { (a, l + 1, tb) };
                            // Cannot fail (see above); a failed push would only skip `far`.
                            let _ = stack.push((far as u32, t_far));
                            node = near;
                            continue 'walk;
                        }
                        (Some(_), None) => {
                            node = a;
                            continue 'walk;
                        }
                        (None, Some(_)) => {
                            node = b;
                            continue 'walk;
                        }
                        (None, None) => {}
                    }
                }
            }
            // Pop the next node still in reach of the current best.
            loop {
                let Some((index, t_near)) = stack.pop() else {
                    break 'walk;
                };
                if t_near <= S::widen(best_t) {
                    if let Some(n) = self.nodes.get(index as usize) {
                        node = n;
                        continue 'walk;
                    }
                }
            }
        }
        (best_t, best_prim, best_at)
    }
}

impl<S: Scalar, P: Primitive<S>> Accel<S> for Bvh<'_, S, P> {
    #[inline]
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>> {
        let (t, prim, slot) = self.traverse::<false, C>(ray, stats);
        Nearest::found(t, prim, slot)
    }

    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> (S, S) {
        found.barycentrics_in(self.prims, ray)
    }

    #[inline]
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        self.traverse::<true, C>(ray, stats).1 != u32::MAX
    }
}
