//! Structural checker for a built tree, called by tests after every build.

use super::{Bvh, MAX_DEPTH, MAX_LEAF_SIZE};
use crate::geom::Primitive;
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
    /// A primitive's box is not inside the leaf that holds it.
    PrimOutsideLeaf {
        /// The leaf.
        node: usize,
        /// The primitive.
        prim: u32,
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
    /// slice in order, every primitive exactly once and inside its leaf, depth within the cap.
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
        let mut stack = [(0usize, 0usize); MAX_DEPTH + 2];
        let mut sp = 1usize;
        let mut next_first = 0usize;
        while sp > 0 {
            sp -= 1;
            let Some(&(index, depth)) = stack.get(sp) else {
                return Err(InvalidTree::TooDeep { depth: sp });
            };
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
                let Some(leaf_ids) = self.prim_ids.get(first..first + count) else {
                    return Err(InvalidTree::BadLeafRange { node: index });
                };
                for (slot, &id) in (first..).zip(leaf_ids) {
                    let at = if self.leaf_order { slot } else { id as usize };
                    let Some(p) = self.prims.get(at) else {
                        return Err(InvalidTree::BadPrimIds { prim: id });
                    };
                    if !node.bounds().contains(&p.bounds()) {
                        return Err(InvalidTree::PrimOutsideLeaf {
                            node: index,
                            prim: id,
                        });
                    }
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
                if !node.bounds().contains(&c.bounds()) {
                    return Err(InvalidTree::ChildOutsideParent { node: child });
                }
                let Some(slot) = stack.get_mut(sp) else {
                    return Err(InvalidTree::TooDeep { depth: depth + 1 });
                };
                *slot = (child, depth + 1);
                sp += 1;
            }
        }
        if next_first != n {
            return Err(InvalidTree::BadLeafRange { node: 0 });
        }
        if stats.depth != self.depth as usize {
            return Err(InvalidTree::TooDeep { depth: stats.depth });
        }
        check_permutation(self.prim_ids).map(|()| stats)
    }
}

/// Every id in `0..ids.len()` exactly once, checked window by window with a fixed bitmap (no
/// allocation): `O(n²/8192)` work, fine for the sizes tests use.
pub(crate) fn check_permutation(ids: &[u32]) -> Result<(), InvalidTree> {
    const WINDOW: usize = 8192;
    let n = ids.len();
    let mut base = 0usize;
    while base < n {
        let mut seen = [0u64; WINDOW / 64];
        for &id in ids {
            let id = id as usize;
            if id >= n {
                return Err(InvalidTree::BadPrimIds { prim: id as u32 });
            }
            if (base..base + WINDOW).contains(&id) {
                let (word, bit) = ((id - base) / 64, (id - base) % 64);
                if seen[word] & (1 << bit) != 0 {
                    return Err(InvalidTree::BadPrimIds { prim: id as u32 });
                }
                seen[word] |= 1 << bit;
            }
        }
        // n distinct in-range ids in total means none is missing, but check each window anyway.
        for k in 0..WINDOW.min(n - base) {
            if seen[k / 64] & (1 << (k % 64)) == 0 {
                return Err(InvalidTree::BadPrimIds {
                    prim: (base + k) as u32,
                });
            }
        }
        base += WINDOW;
    }
    Ok(())
}
