//! A traversal that hands each leaf's primitive ids to the caller instead of testing them: for
//! trees whose primitives are themselves structures (the renderer's tree over its objects).

use super::{Bvh, Node, MAX_DEPTH};
use crate::accel::Counters;
use crate::geom::{Primitive, Ray};
use crate::scalar::Scalar;

impl<S: Scalar, P: Primitive<S>> Bvh<'_, S, P> {
    /// Visits, nearest child first, every leaf whose box the slab test accepts within the
    /// current far end, and calls `visit(id, t_max, stats)` for each primitive id in it. `visit`
    /// returns the new far end (at most `t_max`: the distance of a closer hit it recorded, or
    /// `t_max` unchanged) or `None` to stop the walk. A subtree is skipped only if its entry
    /// lies beyond `widen(far end)`, as in the closest-hit traversal, so every primitive that
    /// could hold a hit at or before the far end is visited.
    pub(crate) fn walk<C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
        mut visit: impl FnMut(u32, S, &mut C) -> Option<S>,
    ) {
        let rd = ray.data();
        let t_min = ray.t_min();
        let mut t_max = ray.t_max();
        let Some(root) = self.nodes.first() else {
            return;
        };
        stats.node();
        if S::slab(rd, &root.lo, &root.hi, t_min, t_max).is_none() {
            return;
        }
        // As in `traverse`: each level below the root pushes at most one entry.
        let mut stack: heapless::Vec<(u32, S), MAX_DEPTH> = heapless::Vec::new();
        let mut node: &Node<S> = root;
        'walk: loop {
            if node.count > 0 {
                let (first, count) = (node.first as usize, node.count as usize);
                let ids = self
                    .prim_ids
                    .get(first..first.saturating_add(count))
                    .unwrap_or_default();
                for &id in ids {
                    stats.prim();
                    match visit(id, t_max, stats) {
                        Some(t) => t_max = t,
                        None => return,
                    }
                }
            } else {
                let l = node.first as usize;
                if let Some([a, b]) = self.nodes.get(l..l + 2) {
                    stats.node();
                    stats.node();
                    let [ta, tb] = S::slab_pair(rd, (&a.lo, &a.hi), (&b.lo, &b.hi), t_min, t_max);
                    match (ta, tb) {
                        (Some(ta), Some(tb)) => {
                            let (near, far, t_far) =
                                if tb < ta { (b, l, ta) } else { (a, l + 1, tb) };
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
            loop {
                let Some((index, t_near)) = stack.pop() else {
                    break 'walk;
                };
                if t_near <= S::widen(t_max) {
                    if let Some(n) = self.nodes.get(index as usize) {
                        node = n;
                        continue 'walk;
                    }
                }
            }
        }
    }
}
