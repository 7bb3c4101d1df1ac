//! Stack-based traversal, near child first. One routine serves closest hit and any hit.

use super::{Bvh, Node, MAX_DEPTH};
use crate::accel::{Accel, Counters, Nearest};
use crate::geom::{closer, Barycentrics, Primitive, Ray};
use crate::scalar::Scalar;

impl<S: Scalar, P: Primitive<S>> Bvh<'_, S, P> {
    /// Walks the tree. With `any`, returns at the first hit in range; otherwise finds the
    /// closest under [`closer`]. Returns (t, prim id, index into `prims`) of the hit;
    /// `prim id == u32::MAX` for none.
    ///
    /// Not inlined: every caller (renderer, host, benchmarks) runs the same machine code, so
    /// their timings differ only by what they do around the walk. `any` is an argument, not a
    /// type parameter, so closest and any hit share that code (one copy in flash): it is
    /// read only when a primitive is hit.
    #[inline(never)]
    fn traverse<C: Counters>(&self, ray: &Ray<S>, stats: &mut C, any: bool) -> (S, u32, usize) {
        let rd = ray.data();
        let t_min = ray.t_min();
        // (t, prim id, index into `prims`) of the best hit so far.
        let mut best = (ray.t_max(), u32::MAX, 0usize);
        let Some(root) = self.nodes.first() else {
            return best;
        };
        stats.node();
        if S::slab(rd, &root.lo, &root.hi, t_min, best.0).is_none() {
            return best;
        }
        // Each level below the root pushes at most one entry, and leaves are at most
        // MAX_DEPTH deep, so the stack cannot overflow. `heapless::Vec` leaves its storage
        // uninitialised: a zeroed array cost a 512-byte memset per ray.
        let mut stack: heapless::Vec<(u32, S), MAX_DEPTH> = heapless::Vec::new();
        let mut node: &Node<S> = root;
        'walk: loop {
            if node.count > 0 {
                let leaf = (node.first as usize, node.count as usize);
                if test_leaf(self.leaf(), leaf, rd, t_min, &mut best, stats, any) {
                    return best;
                }
            } else {
                let l = node.first as usize;
                if let Some([a, b]) = self.nodes.get(l..l + 2) {
                    stats.node();
                    stats.node();
                    let [ta, tb] = S::slab_pair(rd, (&a.lo, &a.hi), (&b.lo, &b.hi), t_min, best.0);
                    match (ta, tb) {
                        (Some(ta), Some(tb)) => {
                            // Any hit: the first child first, unordered (the answer does not
                            // depend on the order of the visits).
                            let (near, far, t_far) = if !any && tb < ta {
                                (b, l, ta)
                            } else {
                                (a, l + 1, tb)
                            };
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
                if t_near <= S::widen(best.0) {
                    if let Some(n) = self.nodes.get(index as usize) {
                        node = n;
                        continue 'walk;
                    }
                }
            }
        }
        best
    }

    /// What [`test_leaf`] reads: the primitive ids, the primitives, and whether they are in
    /// leaf order.
    #[inline(always)]
    fn leaf(&self) -> LeafPrims<'_, P> {
        (self.prim_ids, self.prims, self.leaf_order)
    }
}

/// A BVH's primitive ids, its primitives, and whether `prims[i]` is the primitive with id
/// `prim_ids[i]` (leaf order) rather than the one with id `i`.
pub(crate) type LeafPrims<'a, P> = (&'a [u32], &'a [P], bool);

/// The leaf loop of both BVH traversals (binary and 4-wide): tests the primitives with the ids
/// `prim_ids[first..first + count]`, keeping in `best` (t, prim id, index into `prims`) the
/// closest hit under [`closer`]. With `any`, stores the first hit in range and returns true.
#[inline(always)]
pub(crate) fn test_leaf<S: Scalar, P: Primitive<S>, C: Counters>(
    (prim_ids, prims, leaf_order): LeafPrims<'_, P>,
    (first, count): (usize, usize),
    rd: &S::RayData,
    t_min: S,
    best: &mut (S, u32, usize),
    stats: &mut C,
    any: bool,
) -> bool {
    let ids = prim_ids
        .get(first..first.saturating_add(count))
        .unwrap_or_default();
    for (slot, &id) in (first..).zip(ids) {
        let at = if leaf_order { slot } else { id as usize };
        let Some(prim) = prims.get(at) else {
            continue;
        };
        stats.prim();
        if let Some(t) = prim.hit_t(rd, t_min, best.0) {
            if any {
                *best = (t, id, at);
                return true;
            }
            if closer(t, id, best.0, best.1) {
                *best = (t, id, at);
            }
        }
    }
    false
}

impl<S: Scalar, P: Primitive<S>> Accel<S> for Bvh<'_, S, P> {
    #[inline]
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>> {
        let (t, prim, slot) = self.traverse(ray, stats, false);
        Nearest::found(t, prim, slot)
    }

    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> Barycentrics<S> {
        found.barycentrics_in(self.prims, ray)
    }

    #[inline]
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        self.traverse(ray, stats, true).1 != u32::MAX
    }
}
