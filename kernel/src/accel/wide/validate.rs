//! Structural checker for a collapsed tree, called by tests after every collapse.

use super::node::{ChildSlot, EMPTY_SLOT};
use super::{Bvh4, Bvh8, WideBvh};
use crate::accel::bvh::{
    check_permutation, leaf_bounds, InvalidTree, TreeStats, MAX_DEPTH, MAX_LEAF_SIZE,
};
use crate::geom::Primitive;
use crate::scalar::Scalar;

impl<S: Scalar, P: Primitive<S>> Bvh4<'_, S, P> {
    /// [`WideBvh::check`], with room for `3·MAX_DEPTH` pending children (the traversal bound,
    /// see `traverse.rs`) plus the 4 a node pushes.
    ///
    /// # Errors
    /// The first violation found.
    pub fn validate(&self) -> Result<TreeStats, InvalidTree> {
        self.check::<{ 3 * MAX_DEPTH + 4 }>()
    }
}

impl<S: Scalar, P: Primitive<S>> Bvh8<'_, S, P> {
    /// [`WideBvh::check`], with room for `7·MAX_DEPTH` pending children (the traversal bound,
    /// see `traverse8.rs`) plus the 8 a node pushes.
    ///
    /// # Errors
    /// The first violation found.
    pub fn validate(&self) -> Result<TreeStats, InvalidTree> {
        self.check::<{ 7 * MAX_DEPTH + 8 }>()
    }
}

impl<S: Scalar, P: Primitive<S>, const W: usize> WideBvh<'_, S, P, W> {
    /// Checks every invariant: used slots first and at least two per node (one only for a
    /// root over a single leaf), inner children after their parent and inside its slot box,
    /// every node reached exactly once, leaves tiling the id slice in depth-first order, every
    /// primitive exactly once, every leaf's box holding its primitives' boxes padded by the
    /// traversal margin (as [`crate::Bvh::validate`] checks), wide depth below [`MAX_DEPTH`] and as
    /// recorded. `TreeStats::depth` is the depth of the deepest wide node.
    ///
    /// `STACK` bounds the depth-first work list.
    ///
    /// # Errors
    /// The first violation found.
    fn check<const STACK: usize>(&self) -> Result<TreeStats, InvalidTree> {
        let n = self.prims.len();
        let mut stats = TreeStats {
            node_count: self.nodes.len(),
            ..TreeStats::default()
        };
        if n == 0 || self.nodes.is_empty() {
            return if n == 0 && self.nodes.is_empty() {
                Ok(stats)
            } else {
                Err(InvalidTree::BadLeafRange { node: 0 })
            };
        }
        // Ids first: a permutation of `0..n` indexes a primitive whichever order they are in.
        if self.prim_ids.len() != n {
            return Err(InvalidTree::BadPrimIds { prim: n as u32 });
        }
        check_permutation(self.prim_ids)?;
        // (child, count, depth): count 0 is the node `child`, otherwise a leaf.
        let mut stack = [(0u32, 0u32, 0u32); STACK];
        let mut sp = 1usize;
        let (mut next_first, mut visited) = (0usize, 0usize);
        while sp > 0 {
            sp -= 1;
            let Some(&(child, count, depth)) = stack.get(sp) else {
                return Err(InvalidTree::TooDeep { depth: sp });
            };
            if count > 0 {
                // A leaf, reached in depth-first order: its range continues the previous one.
                let (first, count) = (child as usize, count as usize);
                if first != next_first || count > MAX_LEAF_SIZE as usize || first + count > n {
                    return Err(InvalidTree::BadLeafRange { node: first });
                }
                next_first = first + count;
                continue;
            }
            let index = child as usize;
            let depth = depth as usize;
            if depth >= MAX_DEPTH {
                return Err(InvalidTree::TooDeep { depth });
            }
            stats.depth = stats.depth.max(depth);
            visited += 1;
            let Some(node) = self.nodes.get(index) else {
                return Err(InvalidTree::BadChild { node: index });
            };
            let used = node.child_count();
            let single_leaf_root = index == 0 && used == 1 && node.count[0] > 0;
            if node.used_mask() != (1 << used) - 1 || (used < 2 && !single_leaf_root) {
                return Err(InvalidTree::BadChild { node: index });
            }
            // Push in reverse so slot 0 is visited first.
            for slot in (0..used).rev() {
                let (Some(b), Some(ChildSlot { child: c, count: k })) =
                    (node.bounds(slot), node.slot(slot))
                else {
                    return Err(InvalidTree::BadChild { node: index });
                };
                if k == 0 {
                    let ci = c as usize;
                    let Some(kid) = self.nodes.get(ci).filter(|_| ci > index) else {
                        return Err(InvalidTree::BadChild { node: index });
                    };
                    for s in 0..kid.child_count() {
                        if !kid.bounds(s).is_some_and(|kb| b.contains(&kb)) {
                            return Err(InvalidTree::ChildOutsideParent { node: ci });
                        }
                    }
                } else if k != EMPTY_SLOT {
                    stats.leaf_count += 1;
                    stats.max_leaf_size = stats.max_leaf_size.max(k);
                    let first = c as usize;
                    let leaf = (self.prim_ids, self.prims, self.leaf_order);
                    // `None` only for a range out of bounds (ids are checked above).
                    match leaf_bounds(leaf, (first, k as usize)) {
                        None => return Err(InvalidTree::BadLeafRange { node: first }),
                        Some(lb) if !b.contains(&lb) => {
                            return Err(InvalidTree::LeafTooSmall { node: index })
                        }
                        Some(_) => {}
                    }
                }
                let Some(top) = stack.get_mut(sp) else {
                    return Err(InvalidTree::TooDeep { depth: depth + 1 });
                };
                *top = (c, k, depth as u32 + 1);
                sp += 1;
            }
        }
        if next_first != n || visited != self.nodes.len() {
            return Err(InvalidTree::BadLeafRange { node: 0 });
        }
        if stats.depth != self.depth as usize {
            return Err(InvalidTree::TooDeep { depth: stats.depth });
        }
        Ok(stats)
    }
}
