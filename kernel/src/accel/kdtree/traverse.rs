//! Front-to-back traversal with an explicit stack and early termination.

use super::{KdTree, MAX_DEPTH};
use crate::accel::grid::MAILBOX;
use crate::accel::{Accel, Counters, Nearest};
use crate::geom::{closer, Barycentrics, Primitive, Ray};
use crate::scalar::Scalar;

/// A node still to visit: its index, box and slab entry distance.
#[derive(Clone, Copy)]
struct Entry<S> {
    node: u32,
    t: S,
    lo: [S; 3],
    hi: [S; 3],
}

impl<S: Scalar, P: Primitive<S>> KdTree<'_, S, P> {
    /// Returns (t, prim) of the hit; `prim == u32::MAX` for none.
    ///
    /// Not inlined, as the BVH's and the grid's walks: every caller runs the same machine code,
    /// and a caller that dispatches over accelerators (the renderer) does not carry this walk's
    /// stack in its own frame on every ray.
    #[inline(never)]
    fn traverse<const ANY: bool, C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> (S, u32) {
        let rd = ray.data();
        let t_min = ray.t_min();
        let mut best_t = ray.t_max();
        let mut best_prim = u32::MAX;
        if self.nodes.is_empty() {
            return (best_t, best_prim);
        }
        stats.node();
        let (mut lo, mut hi) = (self.bounds.lo, self.bounds.hi);
        if S::slab(rd, &lo, &hi, t_min, best_t).is_none() {
            return (best_t, best_prim);
        }
        let mut mailbox = [u32::MAX; MAILBOX];
        // One entry per level at most, and leaves are at most MAX_DEPTH deep.
        let mut stack = [Entry {
            node: 0,
            t: S::ZERO,
            lo,
            hi,
        }; MAX_DEPTH as usize];
        let mut sp = 0usize;
        let mut index = 0usize;
        'walk: while let Some(node) = self.nodes.get(index) {
            if node.is_leaf() {
                let first = node.first() as usize;
                let ids = self
                    .refs
                    .get(first..first + node.count as usize)
                    .unwrap_or_default();
                for &id in ids {
                    let slot = id as usize % MAILBOX;
                    if mailbox[slot] == id {
                        continue;
                    }
                    mailbox[slot] = id;
                    let Some(prim) = self.prims.get(id as usize) else {
                        continue;
                    };
                    stats.prim();
                    if let Some(t) = prim.hit_t(rd, t_min, best_t) {
                        if ANY {
                            return (t, id);
                        }
                        if closer(t, id, best_t, best_prim) {
                            best_t = t;
                            best_prim = id;
                        }
                    }
                }
            } else {
                let a = node.axis().min(2);
                let l = node.first();
                let mut below_hi = hi;
                below_hi[a] = node.split;
                let mut above_lo = lo;
                above_lo[a] = node.split;
                stats.node();
                stats.node();
                let [tb, ta] = S::slab_pair(rd, (&lo, &below_hi), (&above_lo, &hi), t_min, best_t);
                match (tb, ta) {
                    (Some(tb), Some(ta)) => {
                        let (far, near_below) = if ta < tb {
                            (
                                Entry {
                                    node: l,
                                    t: tb,
                                    lo,
                                    hi: below_hi,
                                },
                                false,
                            )
                        } else {
                            (
                                Entry {
                                    node: l + 1,
                                    t: ta,
                                    lo: above_lo,
                                    hi,
                                },
                                true,
                            )
                        };
                        if let Some(slot) = stack.get_mut(sp) {
                            *slot = far;
                            sp += 1;
                        }
                        if near_below {
                            index = l as usize;
                            hi = below_hi;
                        } else {
                            index = l as usize + 1;
                            lo = above_lo;
                        }
                        continue 'walk;
                    }
                    (Some(_), None) => {
                        index = l as usize;
                        hi = below_hi;
                        continue 'walk;
                    }
                    (None, Some(_)) => {
                        index = l as usize + 1;
                        lo = above_lo;
                        continue 'walk;
                    }
                    (None, None) => {}
                }
            }
            // Pop the next node still in reach of the best hit.
            loop {
                if sp == 0 {
                    break 'walk;
                }
                sp -= 1;
                // `% MAX_DEPTH`: a no-op (pushes stop at capacity) that keeps the bounds-check
                // panic out of the loop.
                let e = stack[sp % MAX_DEPTH as usize];
                if e.t <= S::widen(best_t) {
                    index = e.node as usize;
                    lo = e.lo;
                    hi = e.hi;
                    continue 'walk;
                }
            }
        }
        (best_t, best_prim)
    }
}

impl<S: Scalar, P: Primitive<S>> Accel<S> for KdTree<'_, S, P> {
    #[inline]
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>> {
        let (t, prim) = self.traverse::<false, C>(ray, stats);
        Nearest::found(t, prim, prim as usize)
    }

    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> Barycentrics<S> {
        found.barycentrics_in(self.prims, ray)
    }

    #[inline]
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        self.traverse::<true, C>(ray, stats).1 != u32::MAX
    }
}
