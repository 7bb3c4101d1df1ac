//! Structural checker for a built tree, called by tests after every build.

use super::{leaf_bounds, Bvh, MAX_DEPTH, MAX_LEAF_SIZE};
use crate::geom::{corners_contain, Primitive};
use crate::scalar::Scalar;
use core::fmt;

/// Shape of a valid tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TreeStats {
    /// Nodes in use.
    pub node_count: usize,
    /// Leaves.
    pub leaf_count: usize,
    /// Depth of the deepest leaf (root = 0).
    pub depth: usize,
    /// Largest leaf.
    pub max_leaf_size: u32,
}

/// The first violated invariant found by [`Bvh::validate`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum InvalidTree {
    /// An inner node's children are out of range or not after it.
    BadChild {
        /// The node.
        node: usize,
    },
    /// A child's box is not inside its parent's.
    ChildOutsideParent {
        /// The child.
        node: usize,
    },
    /// A leaf is empty, too large, or its range is out of bounds or not where the previous
    /// leaf ended (leaves must tile the id slice in order).
    BadLeafRange {
        /// The leaf.
        node: usize,
    },
    /// A leaf's box does not hold its primitives' boxes padded by the traversal margin.
    LeafTooSmall {
        /// The leaf.
        node: usize,
    },
    /// A primitive id is out of range, listed twice, or missing.
    BadPrimIds {
        /// The offending id.
        prim: u32,
    },
    /// A leaf is deeper than [`MAX_DEPTH`], or the recorded depth is wrong.
    TooDeep {
        /// The depth found.
        depth: usize,
    },
}

impl fmt::Display for InvalidTree {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "invalid BVH: {self:?}")
    }
}

impl core::error::Error for InvalidTree {}

impl<S: Scalar, P: Primitive<S>> Bvh<'_, S, P> {
    /// Checks every invariant: children after and inside their parents, leaves tiling the id
    /// slice in order, every primitive exactly once, every leaf's box holding its primitives'
    /// boxes padded by the traversal margin (the padded union `Numerics::pad_bounds` gives, as
    /// the builder and refit compute it), depth within the cap and as recorded. One pass over
    /// the nodes after the id check; a tree that passes answers every query as brute force
    /// over its primitives does.
    ///
    /// # Errors
    /// The first violation found.
    pub fn validate(&self) -> Result<TreeStats, InvalidTree> {
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
        // (node, depth) still to visit; each inner node pushes two, so depth + 2 entries.
        let mut stack: heapless::Vec<(u32, u32), { MAX_DEPTH + 2 }> = heapless::Vec::new();
        let _ = stack.push((0, 0));
        let mut next_first = 0usize;
        while let Some((index, depth)) = stack.pop() {
            let (index, depth) = (index as usize, depth as usize);
            if depth > MAX_DEPTH {
                return Err(InvalidTree::TooDeep { depth });
            }
            stats.depth = stats.depth.max(depth);
            let Some(node) = self.nodes.get(index) else {
                return Err(InvalidTree::BadChild { node: index });
            };
            if node.is_leaf() {
                let (first, count) = (node.first as usize, node.count as usize);
                if first != next_first || count > MAX_LEAF_SIZE as usize || first + count > n {
                    return Err(InvalidTree::BadLeafRange { node: index });
                }
                next_first = first + count;
                stats.leaf_count += 1;
                stats.max_leaf_size = stats.max_leaf_size.max(node.count);
                let leaf = (self.prim_ids, self.prims, self.leaf_order);
                // `None` only for a range or id out of bounds, ruled out above.
                if !leaf_bounds(leaf, (first, count))
                    .is_some_and(|b| corners_contain((&node.lo, &node.hi), (&b.lo, &b.hi)))
                {
                    return Err(InvalidTree::LeafTooSmall { node: index });
                }
                continue;
            }
            let l = node.first as usize;
            if l <= index || l % 2 != 0 || l + 1 >= self.nodes.len() {
                return Err(InvalidTree::BadChild { node: index });
            }
            for child in [l + 1, l] {
                let Some(c) = self.nodes.get(child) else {
                    return Err(InvalidTree::BadChild { node: index });
                };
                if !corners_contain((&node.lo, &node.hi), (&c.lo, &c.hi)) {
                    return Err(InvalidTree::ChildOutsideParent { node: child });
                }
                if stack.push((child as u32, depth as u32 + 1)).is_err() {
                    return Err(InvalidTree::TooDeep { depth: depth + 1 });
                }
            }
        }
        if next_first != n {
            return Err(InvalidTree::BadLeafRange { node: 0 });
        }
        if stats.depth != self.depth as usize {
            return Err(InvalidTree::TooDeep { depth: stats.depth });
        }
        Ok(stats)
    }
}

/// Every id in `0..ids.len()` exactly once: each in range and none twice (`n` distinct ids
/// below `n` are all of them), checked window by window with a fixed bitmap (no allocation):
/// `O(n²/8192)` work, fine for the sizes tests use.
pub(crate) fn check_permutation(ids: &[u32]) -> Result<(), InvalidTree> {
    const WINDOW: usize = 8192;
    let n = ids.len();
    let mut base = 0usize;
    while base < n {
        // `black_box` hides the zero from the optimiser, so the array is filled by a short
        // store loop instead of a call to `memset` (whose routine alone costs more flash than
        // this whole check on a microcontroller).
        let mut seen = [core::hint::black_box(0u32); WINDOW / 32];
        for &id in ids {
            let id = id as usize;
            if id >= n {
                return Err(InvalidTree::BadPrimIds { prim: id as u32 });
            }
            if let Some(word) = id.checked_sub(base).and_then(|k| seen.get_mut(k / 32)) {
                let bit = 1 << ((id - base) % 32);
                if *word & bit != 0 {
                    return Err(InvalidTree::BadPrimIds { prim: id as u32 });
                }
                *word |= bit;
            }
        }
        base += WINDOW;
    }
    Ok(())
}
